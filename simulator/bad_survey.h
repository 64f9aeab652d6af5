// Broken surveys for the bad-input suite (`zebrageo simulate --bad KIND`).
//
// A broken survey is a small, fast simulated survey (short road, 640x480
// images) with one deliberate fault written into it after the simulation.
// truth/meta.json keeps every field the simulator wrote and gains
//   "bad": KIND, "expect": "error" | "warning", "bad_description": "...",
// which is what ../shared/tools/score_results.py badinput reads: on "error"
// `zebrageo run` must exit non-zero with a message and leave no output; on
// "warning" it must exit 0, write every output and list a warning in
// report.json.
#ifndef ZEBRAGEO_SIMULATOR_BAD_SURVEY_H_
#define ZEBRAGEO_SIMULATOR_BAD_SURVEY_H_

#include <string>
#include <vector>

#include "simulator/simulator.h"

namespace zebrageo {

struct BadSurveyKind {
  std::string name;
  // "error" or "warning" (empty_database: either is honest; like a survey
  // without zebra, it gives the uncorrected trajectory and a warning).
  std::string expect;
  std::string description;
};

// Every kind, in a fixed order.
const std::vector<BadSurveyKind>& BadSurveyKinds();
// The kind named `name`, or nullptr.
const BadSurveyKind* FindBadSurveyKind(const std::string& name);

// Sets the small and fast simulation the kind is written into (call after
// ApplyPreset, before --set overrides). Returns "" or an error naming the
// known kinds.
std::string ApplyBadSurveySettings(const std::string& kind,
                                   SimulationOptions* options);

// Writes the fault of `kind` into the simulated survey in `folder` and
// records it in truth/meta.json. Deterministic. Throws std::runtime_error
// when a file cannot be read or written.
void BreakSurvey(const std::string& kind, const std::string& folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SIMULATOR_BAD_SURVEY_H_
