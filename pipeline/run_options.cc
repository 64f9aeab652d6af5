#include "pipeline/run_options.h"

#include "pipeline/exit_codes.h"
#include "survey/input_error.h"
#include "survey/json_file.h"
#include "survey/option_check.h"
#include "survey/option_json.h"

namespace zebrageo {

std::string RunOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, threads, 0);
  OPTION_NESTED(check, boresight);
  OPTION_NESTED(check, reconstruction);
  OPTION_NESTED(check, road_lines);
  OPTION_NESTED(check, matching);
  OPTION_NESTED(check, paint_probe);
  OPTION_NESTED(check, tie_point_matching);
  OPTION_NESTED(check, line_registration);
  OPTION_NESTED(check, adjustment);
  OPTION_NESTED(check, second_pass);
  OPTION_NESTED(check, report);
  return check.problem();
}

nlohmann::json RunOptionsToJson(const RunOptions& options) {
  return OptionsToJson(options);
}

RunOptions RunOptionsFromJson(const nlohmann::json& json,
                              const RunOptions& defaults) {
  RunOptions options;
  try {
    options = OptionsFromJson(json, defaults);
  } catch (const OptionsJsonError& error) {
    throw UsageError(error.what());
  }
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError(problem);
  return options;
}

RunOptions ReadRunOptions(const std::string& path, const RunOptions& defaults) {
  try {
    return RunOptionsFromJson(ReadJsonFile(path, path), defaults);
  } catch (const InputError& error) {
    throw UsageError(std::string("--options: ") + error.what());
  } catch (const UsageError& error) {
    throw UsageError("--options " + path + ": " + error.what());
  }
}

}  // namespace zebrageo
