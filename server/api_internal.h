// What the route handlers of the server share (internal to server/).
#ifndef ZEBRAGEO_SERVER_API_INTERNAL_H_
#define ZEBRAGEO_SERVER_API_INTERNAL_H_

#include <httplib.h>

#include <nlohmann/json.hpp>
#include <string>

#include "server/job_runner.h"
#include "server/job_store.h"
#include "server/metrics.h"
#include "server/server.h"

namespace zebrageo {

struct ApiContext {
  ServerOptions options;
  std::string root;   // the data root, canonical
  std::string token;  // "" when none is required
  JobStore* store = nullptr;
  JobRunner* runner = nullptr;
  Metrics* metrics = nullptr;
  double started_at = 0.0;
};

// A JSON error body {"error": message, "status": status}.
void SendError(httplib::Response& res, int status, const std::string& message);
void SendJson(httplib::Response& res, int status, const nlohmann::json& body);
// Whether the request carries the token: "Authorization: Bearer T", or
// for GET the cookie zebrageo_token=T that the web page sets.
bool Authorized(const ApiContext& context, const httplib::Request& req);

// Route handlers (server/api_jobs.cc, server/api_files.cc,
// server/web_page.cc). Each answers every bad request with a 4xx JSON error.
void CreateJob(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res, const httplib::ContentReader& reader);
void ListJobs(const ApiContext& context, const httplib::Request& req,
              httplib::Response& res);
void GetJob(const ApiContext& context, const httplib::Request& req,
            httplib::Response& res);
void CancelJob(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res);
void DeleteJob(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res);
void GetLog(const ApiContext& context, const httplib::Request& req,
            httplib::Response& res);
void ListResults(const ApiContext& context, const httplib::Request& req,
                 httplib::Response& res);
void GetResultFile(const ApiContext& context, const httplib::Request& req,
                   httplib::Response& res);
void GetResultsZip(const ApiContext& context, const httplib::Request& req,
                   httplib::Response& res);
void GetReport(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res);
void GetPage(const ApiContext& context, const httplib::Request& req,
             httplib::Response& res);
void GetPageScript(const ApiContext& context, const httplib::Request& req,
                   httplib::Response& res);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_API_INTERNAL_H_
