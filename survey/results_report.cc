#include "survey/results_report.h"

#include "survey/atomic_file.h"

namespace zebrageo {

void WriteReportJson(const nlohmann::json& report, const std::string& path) {
  WriteFileAtomically(
      path, [&](std::ostream& out) { out << report.dump(1) << "\n"; });
}

void WriteReportHtml(const std::string& html, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << html; });
}

}  // namespace zebrageo
