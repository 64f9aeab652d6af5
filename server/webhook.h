// The callback URL of a job, called when it ends, as NodeODM calls a
// task's webhook: an HTTP POST of the job's JSON (as GET /jobs/{id} shows
// it), retried with a growing delay until the receiver answers 2xx. A
// delivery still pending when the server stops is kept in the job store
// and made by the restarted server.
#ifndef ZEBRAGEO_SERVER_WEBHOOK_H_
#define ZEBRAGEO_SERVER_WEBHOOK_H_

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace zebrageo {

// "" when `url` is an http:// or https:// URL a webhook may have,
// otherwise what is wrong with it.
std::string WebhookUrlProblem(const std::string& url);

struct WebhookOptions {
  int attempts = 5;
  double first_delay_s = 2.0;  // doubled after each failed attempt
  double timeout_s = 10.0;     // of one attempt
};

class WebhookSender {
 public:
  // `body` gives the job's JSON text (nullopt: the job was deleted, the
  // delivery is dropped); `delivered` records the outcome of a delivery
  // (true: made; false: every attempt failed).
  WebhookSender(
      WebhookOptions options,
      std::function<std::optional<std::string>(const std::string&)> body,
      std::function<void(const std::string&, bool)> delivered);
  ~WebhookSender();
  WebhookSender(const WebhookSender&) = delete;
  WebhookSender& operator=(const WebhookSender&) = delete;

  void Send(const std::string& job_id, const std::string& url);

 private:
  struct Delivery {
    std::string job_id;
    std::string url;
    int attempt = 0;
    std::chrono::steady_clock::time_point due;
  };
  void Loop();
  bool Post(const Delivery& delivery, const std::string& body) const;

  WebhookOptions options_;
  std::function<std::optional<std::string>(const std::string&)> body_;
  std::function<void(const std::string&, bool)> delivered_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Delivery> queue_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_WEBHOOK_H_
