// GET / and GET /app.js: the server's web page. The table of jobs is
// rendered by the server; app.js (no build step, no library) refreshes it
// from GET /jobs every second and a half, and sends cancels. With a token
// required, the page asks for it once and keeps it in a cookie that the
// server accepts for GET requests only (a cross-site form cannot cancel a
// job); the script sends it as a bearer token for the rest.
#include <ctime>
#include <sstream>

#include "pipeline/version.h"
#include "server/api_internal.h"

namespace zebrageo {
namespace {

std::string Escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string UtcTime(double seconds) {
  const time_t t = static_cast<time_t>(seconds);
  tm utc{};
  gmtime_r(&t, &utc);
  char text[32];
  strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S", &utc);
  return text;
}

constexpr char kStyle[] = R"(
body { font-family: system-ui, sans-serif; margin: 2em; color: #222; }
h1 { font-size: 1.4em; } h1 small { color: #777; font-weight: normal; }
table { border-collapse: collapse; width: 100%; }
th, td { text-align: left; padding: 0.35em 0.6em; border-bottom: 1px solid #ddd; }
th { background: #f4f4f4; }
.state { padding: 0.1em 0.5em; border-radius: 0.8em; font-size: 0.9em; }
.queued { background: #eee; } .running { background: #cde4ff; }
.done { background: #c8f0c8; } .failed { background: #ffd0d0; }
.cancelled { background: #f0e0c0; }
.bar { width: 9em; height: 0.8em; background: #eee; border-radius: 0.4em; }
.bar div { height: 100%; background: #3a7bd5; border-radius: 0.4em; }
.error { color: #a00; font-size: 0.9em; }
form { margin: 1em 0; padding: 0.8em; background: #f8f8f8; }
)";

// One job's row; the script renders the same cells (app.js, Row()).
std::string JobRow(const Job& job) {
  std::ostringstream row;
  const std::string id = Escaped(job.id);
  row << "<tr id='job-" << id << "'>"
      << "<td><a href='/jobs/" << id << "'>" << id << "</a></td>"
      << "<td>" << Escaped(job.name) << "</td>"
      << "<td><span class='state " << JobStateName(job.state) << "'>"
      << JobStateName(job.state) << "</span></td>"
      << "<td>" << Escaped(job.stage) << "</td>"
      << "<td><div class='bar'><div style='width:"
      << static_cast<int>(job.progress * 100) << "%'></div></div></td>"
      << "<td>" << UtcTime(job.created_at) << "</td><td>";
  if (job.state == JobState::kDone) {
    row << "<a href='/jobs/" << id << "/report'>report</a> "
        << "<a href='/jobs/" << id << "/results.zip'>results.zip</a> ";
  }
  row << "<a href='/jobs/" << id << "/log'>log</a>";
  if (!IsFinal(job.state)) {
    row << " <button data-cancel='" << id << "'>cancel</button>";
  }
  if (!job.error.empty()) {
    row << "<div class='error'>" << Escaped(job.error) << "</div>";
  }
  row << "</td></tr>\n";
  return row.str();
}

constexpr char kScript[] = R"JS('use strict';
// zebrageo serve's page: refreshes the table of jobs from GET /jobs.
function token() {
  const m = document.cookie.match(/(?:^|;\s*)zebrageo_token=([^;]*)/);
  return m ? decodeURIComponent(m[1]) : '';
}
function headers() {
  const t = token();
  return t ? { 'Authorization': 'Bearer ' + t } : {};
}
function cell(row, content) {
  const td = document.createElement('td');
  if (typeof content === 'string') td.textContent = content;
  else if (content) td.append(...content);
  row.append(td);
}
function link(href, text) {
  const a = document.createElement('a');
  a.href = href; a.textContent = text;
  return a;
}
function time(seconds) {
  return new Date(seconds * 1000).toISOString().slice(0, 19).replace('T', ' ');
}
function Row(job) {
  const row = document.createElement('tr');
  row.id = 'job-' + job.id;
  cell(row, [link('/jobs/' + job.id, job.id)]);
  cell(row, job.name);
  const state = document.createElement('span');
  state.className = 'state ' + job.state;
  state.textContent = job.state;
  cell(row, [state]);
  cell(row, job.stage || '');
  const bar = document.createElement('div');
  bar.className = 'bar';
  const fill = document.createElement('div');
  fill.style.width = Math.round(job.progress * 100) + '%';
  bar.append(fill);
  cell(row, [bar]);
  cell(row, time(job.created_at));
  const actions = [];
  if (job.state === 'done') {
    actions.push(link(job.links.report, 'report'), ' ',
                 link(job.links.results_zip, 'results.zip'), ' ');
  }
  actions.push(link(job.links.log, 'log'));
  if (!['done', 'failed', 'cancelled'].includes(job.state)) {
    const button = document.createElement('button');
    button.dataset.cancel = job.id;
    button.textContent = 'cancel';
    actions.push(' ', button);
  }
  if (job.error) {
    const error = document.createElement('div');
    error.className = 'error';
    error.textContent = job.error;
    actions.push(error);
  }
  cell(row, actions);
  return row;
}
async function refresh() {
  const status = document.getElementById('status');
  try {
    const response = await fetch('/jobs', { headers: headers() });
    if (!response.ok) throw new Error('GET /jobs: ' + response.status);
    const body = await response.json();
    const rows = document.getElementById('jobs');
    rows.replaceChildren(...body.jobs.slice().reverse().map(Row));
    status.textContent = body.jobs.length + ' jobs, updated ' +
                         new Date().toLocaleTimeString();
    document.body.dataset.refreshes =
        String(Number(document.body.dataset.refreshes || 0) + 1);
  } catch (error) {
    status.textContent = String(error);
  }
}
document.addEventListener('click', async (event) => {
  const id = event.target.dataset && event.target.dataset.cancel;
  if (!id) return;
  await fetch('/jobs/' + id + '/cancel', { method: 'POST', headers: headers() });
  refresh();
});
const login = document.getElementById('login');
if (login) {
  login.addEventListener('submit', (event) => {
    event.preventDefault();
    const value = document.getElementById('token').value;
    document.cookie = 'zebrageo_token=' + encodeURIComponent(value) +
                      '; path=/; SameSite=Strict';
    location.reload();
  });
} else {
  const upload = document.getElementById('upload');
  upload.addEventListener('submit', async (event) => {
    event.preventDefault();
    const response = await fetch('/jobs', {
      method: 'POST', headers: headers(), body: new FormData(upload) });
    const body = await response.json();
    document.getElementById('status').textContent =
        response.ok ? 'job ' + body.id + ' queued' : body.error;
    refresh();
  });
  setInterval(refresh, 1500);
}
)JS";

}  // namespace

void GetPage(const ApiContext& context, const httplib::Request& req,
             httplib::Response& res) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
       << "<title>zebrageo serve</title>"
       << "<link rel='icon' href='data:,'><style>" << kStyle
       << "</style></head>\n<body>\n<h1>zebrageo serve <small>"
       << ZEBRAGEO_VERSION_STRING << ", " << context.options.workers
       << " workers</small></h1>\n";
  if (!Authorized(context, req)) {
    html << "<form id='login'><label>Token <input id='token' "
            "type='password' autocomplete='off'></label> "
            "<button>Sign in</button></form>\n";
  } else {
    html << "<form id='upload'><label>Survey archive (tar or zip) <input "
            "type='file' name='survey' required></label> <label>Name <input "
            "name='name'></label> <button>Submit</button></form>\n"
         << "<p id='status'></p>\n<table><thead><tr><th>Job</th><th>Name</th>"
            "<th>State</th><th>Stage</th><th>Progress</th><th>Created "
            "(UTC)</th><th></th></tr></thead>\n<tbody id='jobs'>\n";
    std::vector<Job> jobs = context.runner->List(std::nullopt);
    for (auto it = jobs.rbegin(); it != jobs.rend(); ++it) html << JobRow(*it);
    html << "</tbody></table>\n";
  }
  html << "<p><a href='/openapi.json'>API (OpenAPI)</a> · "
          "<a href='/metrics'>metrics</a></p>\n"
       << "<script src='/app.js'></script>\n</body></html>\n";
  res.set_header("Content-Security-Policy",
                 "default-src 'self'; img-src 'self' data:; "
                 "style-src 'self' 'unsafe-inline'; "
                 "frame-ancestors 'none'");
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_content(html.str(), "text/html; charset=utf-8");
}

void GetPageScript(const ApiContext&, const httplib::Request&,
                   httplib::Response& res) {
  res.set_content(kScript, "text/javascript; charset=utf-8");
}

}  // namespace zebrageo
