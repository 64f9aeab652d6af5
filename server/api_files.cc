// The files of a job: GET /jobs/{id}/log, /results, /results/{file},
// /results.zip and /report.
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>

#include "server/api_internal.h"
#include "server/archive.h"
#include "server/confined_path.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Files of a results folder that are the server's or the run's own
// bookkeeping, never served: the lock and killed runs' temporaries.
bool IsResultFile(const std::string& name) {
  const std::string base = fs::path(name).filename().string();
  return base != ".zebrageo.lock" && base.find(".tmp-") == std::string::npos;
}

std::string ContentTypeOf(const std::string& name) {
  static const std::map<std::string, std::string> kTypes = {
      {".csv", "text/csv; charset=utf-8"},
      {".json", "application/json"},
      {".geojson", "application/geo+json"},
      {".html", "text/html; charset=utf-8"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".txt", "text/plain; charset=utf-8"},
      {".log", "text/plain; charset=utf-8"},
      {".gpkg", "application/geopackage+sqlite3"},
      {".zip", "application/zip"}};
  auto it = kTypes.find(fs::path(name).extension().string());
  return it == kTypes.end() ? "application/octet-stream" : it->second;
}

// Streams the file at `path` (already confined) as the response.
void SendFile(httplib::Response& res, const std::string& path,
              const std::string& content_type) {
  auto in = std::make_shared<std::ifstream>(path, std::ios::binary);
  std::error_code error;
  const auto size = fs::file_size(path, error);
  if (!*in || error) return SendError(res, 404, "not found");
  res.status = 200;
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_content_provider(
      static_cast<size_t>(size), content_type,
      [in](size_t offset, size_t length, httplib::DataSink& sink) {
        std::vector<char> buffer(std::min<size_t>(length, 1 << 16));
        in->seekg(static_cast<std::streamoff>(offset));
        in->read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        const std::streamsize got = in->gcount();
        if (got <= 0) return false;
        sink.write(buffer.data(), static_cast<size_t>(got));
        return true;
      });
}

// The job of the request, or a 404 already sent.
std::optional<Job> JobOf(const ApiContext& context, const httplib::Request& req,
                         httplib::Response& res) {
  std::optional<Job> job = context.runner->Get(req.matches[1]);
  if (!job) SendError(res, 404, "no job " + req.matches[1].str());
  return job;
}

// The canonical results folder of a job, or "" (and a 404 sent).
std::string ResultsFolder(const ApiContext& context, const Job& job,
                          httplib::Response& res) {
  std::string problem;
  const std::optional<std::string> folder =
      ResolveInside(context.root, "jobs/" + job.id + "/results", &problem);
  if (!folder) {
    SendError(res, 404, "job " + job.id + " has no results yet");
    return "";
  }
  return *folder;
}

}  // namespace

void GetLog(const ApiContext& context, const httplib::Request& req,
            httplib::Response& res) {
  const std::optional<Job> job = JobOf(context, req, res);
  if (!job) return;
  int lines = 200;
  if (req.has_param("tail")) {
    const std::string text = req.get_param_value("tail");
    if (text.empty() || text.size() > 6 ||
        !std::all_of(text.begin(), text.end(), ::isdigit) ||
        std::stoi(text) < 1 || std::stoi(text) > 100000) {
      return SendError(res, 400, "tail: a number of lines from 1 to 100000");
    }
    lines = std::stoi(text);
  }
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_content(LogTail(context.runner->FilesOf(job->id).Log(), lines),
                  "text/plain; charset=utf-8");
}

void ListResults(const ApiContext& context, const httplib::Request& req,
                 httplib::Response& res) {
  const std::optional<Job> job = JobOf(context, req, res);
  if (!job) return;
  const std::string folder = ResultsFolder(context, *job, res);
  if (folder.empty()) return;
  json files = json::array();
  std::vector<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.is_symlink()) continue;
    const std::string name = fs::relative(entry.path(), folder).string();
    if (IsResultFile(name)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    std::error_code error;
    files.push_back({{"name", name},
                     {"size", fs::file_size(folder + "/" + name, error)},
                     {"url", "/jobs/" + job->id + "/results/" + name}});
  }
  SendJson(res, 200, {{"id", job->id}, {"files", files}});
}

void GetResultFile(const ApiContext& context, const httplib::Request& req,
                   httplib::Response& res) {
  const std::optional<Job> job = JobOf(context, req, res);
  if (!job) return;
  const std::string name = req.matches[2];
  std::string problem = RelativePathProblem(name);
  if (!problem.empty()) {
    return SendError(res, 400, "file '" + name + "': " + problem);
  }
  const std::string folder = ResultsFolder(context, *job, res);
  if (folder.empty()) return;
  const std::optional<std::string> path = ResolveInside(folder, name, &problem);
  if (!path || !IsResultFile(name) ||
      !fs::is_regular_file(fs::symlink_status(*path))) {
    return SendError(res, 404,
                     "job " + job->id + " has no result '" + name + "'");
  }
  SendFile(res, *path, ContentTypeOf(name));
}

void GetReport(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res) {
  const std::optional<Job> job = JobOf(context, req, res);
  if (!job) return;
  const std::string folder = ResultsFolder(context, *job, res);
  if (folder.empty()) return;
  const std::string path = folder + "/report.html";
  if (!fs::is_regular_file(fs::symlink_status(path))) {
    return SendError(res, 404, "job " + job->id + " has no report yet");
  }
  SendFile(res, path, "text/html; charset=utf-8");
}

void GetResultsZip(const ApiContext& context, const httplib::Request& req,
                   httplib::Response& res) {
  const std::optional<Job> job = JobOf(context, req, res);
  if (!job) return;
  if (!IsFinal(job->state)) {
    return SendError(res, 409,
                     "job " + job->id + " is " + JobStateName(job->state) +
                         ": its results are zipped once it has ended");
  }
  const std::string folder = ResultsFolder(context, *job, res);
  if (folder.empty()) return;
  const std::string zip = context.runner->FilesOf(job->id).ResultsZip();
  // Built once per job (an ended job's results no longer change); requests
  // racing to build it each write their own temporary file.
  if (!fs::is_regular_file(zip)) {
    try {
      WriteZipOfFolder(folder, "results-" + job->id, IsResultFile, zip);
    } catch (const std::exception& error) {
      return SendError(res, 500, std::string("zip: ") + error.what());
    }
  }
  res.set_header("Content-Disposition",
                 "attachment; filename=\"results-" + job->id + ".zip\"");
  SendFile(res, zip, "application/zip");
}

}  // namespace zebrageo
