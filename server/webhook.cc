#include "server/webhook.h"

#include <httplib.h>

#include <algorithm>
#include <cmath>
#include <regex>

namespace zebrageo {
namespace {

// scheme://host[:port] and the path (with query) of a URL.
bool SplitUrl(const std::string& url, std::string* origin, std::string* path) {
  static const std::regex kUrl(
      R"(^(https?://[A-Za-z0-9.\-]+(:[0-9]{1,5})?|https?://\[[0-9A-Fa-f:.]+\](:[0-9]{1,5})?)(/[^\s#]*)?$)");
  std::smatch match;
  if (!std::regex_match(url, match, kUrl)) return false;
  *origin = match[1].str();
  *path = match[4].matched ? match[4].str() : "/";
  return true;
}

}  // namespace

std::string WebhookUrlProblem(const std::string& url) {
  if (url.size() > 2048) return "webhook: longer than 2048 characters";
  std::string origin, path;
  if (!SplitUrl(url, &origin, &path)) {
    return "webhook: not an http:// or https:// URL";
  }
  return "";
}

WebhookSender::WebhookSender(
    WebhookOptions options,
    std::function<std::optional<std::string>(const std::string&)> body,
    std::function<void(const std::string&, bool)> delivered)
    : options_(options),
      body_(std::move(body)),
      delivered_(std::move(delivered)),
      thread_([this] { Loop(); }) {}

WebhookSender::~WebhookSender() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void WebhookSender::Send(const std::string& job_id, const std::string& url) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back({job_id, url, 0, std::chrono::steady_clock::now()});
  }
  wake_.notify_all();
}

bool WebhookSender::Post(const Delivery& delivery,
                         const std::string& body) const {
  std::string origin, path;
  if (!SplitUrl(delivery.url, &origin, &path)) return false;
  httplib::Client client(origin);
  const auto timeout =
      std::chrono::milliseconds(static_cast<long>(options_.timeout_s * 1000.0));
  client.set_connection_timeout(timeout);
  client.set_read_timeout(timeout);
  client.set_write_timeout(timeout);
  const httplib::Result result = client.Post(path, body, "application/json");
  return result && result->status >= 200 && result->status < 300;
}

void WebhookSender::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    if (queue_.empty()) {
      wake_.wait(lock);
      continue;
    }
    auto next = std::min_element(
        queue_.begin(), queue_.end(),
        [](const Delivery& a, const Delivery& b) { return a.due < b.due; });
    if (next->due > std::chrono::steady_clock::now()) {
      wake_.wait_until(lock, next->due);
      continue;
    }
    Delivery delivery = *next;
    queue_.erase(next);
    lock.unlock();
    const std::optional<std::string> body = body_(delivery.job_id);
    bool done = !body.has_value();
    if (body) {
      if (Post(delivery, *body)) {
        delivered_(delivery.job_id, true);
        done = true;
      } else if (++delivery.attempt >= options_.attempts) {
        delivered_(delivery.job_id, false);
        done = true;
      }
    }
    lock.lock();
    if (!done) {
      const double delay =
          options_.first_delay_s * std::pow(2.0, delivery.attempt - 1);
      delivery.due = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(static_cast<long>(delay * 1e3));
      queue_.push_back(delivery);
    }
  }
}

}  // namespace zebrageo
