// POST /jobs, GET /jobs, GET /jobs/{id}, POST /jobs/{id}/cancel,
// DELETE /jobs/{id}.
#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "server/api_internal.h"
#include "server/archive.h"
#include "server/confined_path.h"
#include "server/webhook.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr size_t kMaxFieldBytes = 64 * 1024;

double NowSeconds() {
  return std::chrono::duration<double>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string NewJobId() {
  std::random_device device;  // getrandom(2)
  std::uniform_int_distribution<uint64_t> bits;
  char text[17];
  snprintf(text, sizeof(text), "%016llx",
           static_cast<unsigned long long>(bits(device)));
  return text;
}

// A POST /jobs request as received: form fields and the uploaded archive
// (streamed to a file), or the JSON body.
struct Submission {
  std::map<std::string, std::string> fields;
  std::string upload_path;  // "" when no archive was sent
  int64_t upload_bytes = 0;
  std::string problem;  // why reading it failed
  int status = 400;
};

// Reads a multipart/form-data body: the part named "survey" (a file) goes
// to `upload_path`, the others (options, webhook, name, folder) to fields.
void ReadMultipart(const ApiContext& context,
                   const httplib::ContentReader& reader,
                   const std::string& upload_path, Submission* submission) {
  std::string part;
  int file = -1;
  const bool read = reader(
      [&](const httplib::MultipartFormData& header) {
        part = header.name;
        if (part == "survey") {
          if (file >= 0 || header.filename.empty()) {
            submission->problem = "survey: one archive file expected";
            return false;
          }
          file =
              open(upload_path.c_str(),
                   O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
          if (file < 0) {
            submission->problem = "the upload cannot be stored";
            submission->status = 500;
            return false;
          }
          submission->upload_path = upload_path;
          return true;
        }
        if (part != "options" && part != "webhook" && part != "name" &&
            part != "folder") {
          submission->problem = "unknown form field '" + part +
                                "' (expected survey, options, webhook, name "
                                "or folder)";
          return false;
        }
        return submission->fields.emplace(part, "").second ||
               (submission->problem = "field '" + part + "' given twice",
                false);
      },
      [&](const char* data, size_t length) {
        if (part == "survey") {
          submission->upload_bytes += static_cast<int64_t>(length);
          if (submission->upload_bytes > context.options.max_upload_bytes) {
            submission->problem =
                "the upload is larger than the server's limit of " +
                std::to_string(context.options.max_upload_bytes) + " bytes";
            submission->status = 413;
            return false;
          }
          for (size_t written = 0; written < length;) {
            const ssize_t n = write(file, data + written, length - written);
            if (n <= 0) {
              submission->problem = "the upload cannot be stored";
              submission->status = 507;
              return false;
            }
            written += static_cast<size_t>(n);
          }
          return true;
        }
        std::string& value = submission->fields[part];
        if (value.size() + length > kMaxFieldBytes) {
          submission->problem = "field '" + part + "' is longer than " +
                                std::to_string(kMaxFieldBytes) + " bytes";
          submission->status = 413;
          return false;
        }
        value.append(data, length);
        return true;
      });
  if (file >= 0) close(file);
  if (!read && submission->problem.empty()) {
    submission->problem = "the request body could not be read";
  }
}

// Reads an application/json body {"folder", "options", "webhook", "name"}.
void ReadJsonBody(const ApiContext& context,
                  const httplib::ContentReader& reader,
                  Submission* submission) {
  std::string body;
  const bool read = reader([&](const char* data, size_t length) {
    if (body.size() + length >
        static_cast<size_t>(context.options.max_json_bytes)) {
      submission->problem = "the JSON body is larger than " +
                            std::to_string(context.options.max_json_bytes) +
                            " bytes";
      submission->status = 413;
      return false;
    }
    body.append(data, length);
    return true;
  });
  if (!read) {
    if (submission->problem.empty()) {
      submission->problem = "the request body could not be read";
    }
    return;
  }
  const json parsed = json::parse(body, nullptr, false);
  if (parsed.is_discarded() || !parsed.is_object()) {
    submission->problem = "the body is not a JSON object";
    return;
  }
  for (const auto& [key, value] : parsed.items()) {
    if (key != "folder" && key != "options" && key != "webhook" &&
        key != "name") {
      submission->problem = "unknown field '" + key +
                            "' (expected folder, options, webhook or name)";
      return;
    }
    if (key == "options") {
      submission->fields[key] = value.dump();
    } else if (value.is_string()) {
      submission->fields[key] = value.get<std::string>();
    } else if (!value.is_null()) {
      submission->problem = "field '" + key + "' must be a string";
      return;
    }
  }
}

// The survey folder inside an extracted upload: the folder itself or its
// only subfolder, whichever holds survey.yaml.
std::string SurveyFolderIn(const std::string& folder) {
  if (fs::is_regular_file(fs::symlink_status(folder + "/survey.yaml"))) {
    return folder;
  }
  std::vector<fs::path> children;
  for (const auto& entry : fs::directory_iterator(folder)) {
    children.push_back(entry.path());
  }
  if (children.size() == 1 &&
      fs::is_directory(fs::symlink_status(children[0])) &&
      fs::is_regular_file(fs::symlink_status(children[0] / "survey.yaml"))) {
    return children[0].string();
  }
  return "";
}

// Checks the fields shared by both kinds of submission into `job`; "" or
// the problem.
std::string ApplyFields(const Submission& submission, Job* job) {
  const auto field = [&](const std::string& key) -> std::string {
    auto it = submission.fields.find(key);
    return it == submission.fields.end() ? "" : it->second;
  };
  job->name = field("name");
  if (job->name.size() > 200) return "name: longer than 200 characters";
  for (char c : job->name) {
    if (static_cast<unsigned char>(c) < 0x20) {
      return "name: has a control character";
    }
  }
  job->webhook = field("webhook");
  if (!job->webhook.empty()) {
    const std::string problem = WebhookUrlProblem(job->webhook);
    if (!problem.empty()) return problem;
  }
  const std::string options = field("options");
  if (!options.empty()) {
    job->options = json::parse(options, nullptr, false);
    if (job->options.is_discarded()) return "options: not valid JSON";
  }
  return RunOptionsProblem(job->options);
}

// The folder job's survey: `folder` relative to the data root, inside it,
// not in the server's own jobs/, with no link out of the root.
std::string ResolveFolder(const ApiContext& context, const std::string& folder,
                          std::string* survey) {
  std::string problem;
  const std::optional<std::string> resolved =
      ResolveInside(context.root, folder, &problem);
  if (!resolved) return "folder '" + folder + "': " + problem;
  if (IsInside(context.root + "/jobs", *resolved) ||
      *resolved == context.root) {
    return "folder '" + folder + "': not a survey folder of the data root";
  }
  if (!fs::is_directory(*resolved)) {
    return "folder '" + folder + "': not a folder";
  }
  if (!fs::is_regular_file(*resolved + "/survey.yaml")) {
    return "folder '" + folder + "': has no survey.yaml";
  }
  problem = FolderEscapeProblem(*resolved, context.root);
  if (!problem.empty()) return "folder '" + folder + "': " + problem;
  *survey = *resolved;
  return "";
}

}  // namespace

void CreateJob(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res, const httplib::ContentReader& reader) {
  if (context.store->CountByState()[JobState::kQueued] >=
      context.options.max_queued_jobs) {
    SendError(res, 503,
              "the queue is full (" +
                  std::to_string(context.options.max_queued_jobs) +
                  " jobs); try again later");
    return;
  }
  Job job;
  job.id = NewJobId();
  job.created_at = NowSeconds();
  const JobFiles files = context.runner->FilesOf(job.id);
  fs::create_directories(files.folder);
  bool keep = false;
  struct Cleanup {
    const std::string& folder;
    bool& keep;
    ~Cleanup() {
      std::error_code ignored;
      if (!keep) fs::remove_all(folder, ignored);
    }
  } cleanup{files.folder, keep};

  Submission submission;
  const std::string type = req.get_header_value("Content-Type");
  if (req.is_multipart_form_data()) {
    ReadMultipart(context, reader, files.folder + "/upload", &submission);
  } else if (type.compare(0, 16, "application/json") == 0) {
    ReadJsonBody(context, reader, &submission);
  } else {
    SendError(res, 415,
              "POST /jobs takes multipart/form-data (an archive as 'survey') "
              "or application/json (a 'folder' under the data root)");
    return;
  }
  if (!submission.problem.empty()) {
    SendError(res, submission.status, submission.problem);
    return;
  }
  std::string problem = ApplyFields(submission, &job);
  if (!problem.empty()) {
    SendError(res, 400, problem);
    return;
  }
  const bool has_folder = submission.fields.count("folder") > 0;
  const bool has_upload = !submission.upload_path.empty();
  if (has_folder == has_upload) {
    SendError(res, 400,
              "give the survey either as an archive ('survey' file) or as a "
              "'folder' under the data root");
    return;
  }
  if (has_upload) {
    job.source = JobSource::kUpload;
    ArchiveLimits limits;
    limits.max_total_bytes = context.options.max_extracted_bytes;
    problem = ArchiveProblem(submission.upload_path, limits);
    if (problem.empty()) {
      try {
        ExtractArchive(submission.upload_path, files.Survey(), limits);
      } catch (const std::exception& error) {
        problem = error.what();
      }
    }
    fs::remove(submission.upload_path);
    if (!problem.empty()) {
      SendError(res, 400, "survey archive: " + problem);
      return;
    }
    job.survey_path = SurveyFolderIn(files.Survey());
    if (job.survey_path.empty()) {
      SendError(res, 400,
                "survey archive: no survey.yaml at its top or in its only "
                "folder");
      return;
    }
  } else {
    job.source = JobSource::kFolder;
    job.folder = submission.fields.at("folder");
    problem = ResolveFolder(context, job.folder, &job.survey_path);
    if (!problem.empty()) {
      SendError(res, 400, problem);
      return;
    }
  }
  if (job.name.empty()) {
    job.name =
        has_folder ? job.folder : fs::path(job.survey_path).filename().string();
  }
  context.store->Insert(job);
  keep = true;
  context.runner->Wake();
  res.set_header("Location", "/jobs/" + job.id);
  SendJson(res, 201, JobToJson(job));
}

void ListJobs(const ApiContext& context, const httplib::Request& req,
              httplib::Response& res) {
  std::optional<JobState> state;
  if (req.has_param("state")) {
    state = JobStateFromName(req.get_param_value("state"));
    if (!state) {
      SendError(res, 400,
                "state: one of queued, running, done, failed, cancelled");
      return;
    }
  }
  json jobs = json::array();
  for (const Job& job : context.runner->List(state)) {
    jobs.push_back(JobToJson(job));
  }
  SendJson(res, 200, {{"jobs", jobs}});
}

void GetJob(const ApiContext& context, const httplib::Request& req,
            httplib::Response& res) {
  const std::optional<Job> job = context.runner->Get(req.matches[1]);
  if (!job) return SendError(res, 404, "no job " + req.matches[1].str());
  SendJson(res, 200, JobToJson(*job));
}

void CancelJob(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res) {
  const std::optional<Job> job = context.runner->Cancel(req.matches[1]);
  if (!job) return SendError(res, 404, "no job " + req.matches[1].str());
  SendJson(res, 200, JobToJson(*job));
}

void DeleteJob(const ApiContext& context, const httplib::Request& req,
               httplib::Response& res) {
  switch (context.runner->Delete(req.matches[1])) {
    case JobRunner::DeleteOutcome::kUnknown:
      return SendError(res, 404, "no job " + req.matches[1].str());
    case JobRunner::DeleteOutcome::kStillRunning:
      return SendError(res, 409,
                       "the job's worker has not ended yet; try again");
    case JobRunner::DeleteOutcome::kDeleted:
      return SendJson(res, 200,
                      {{"id", req.matches[1].str()}, {"deleted", true}});
  }
}

}  // namespace zebrageo
