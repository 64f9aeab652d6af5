// Issue 43 on a survey of the field's long-outage kind (the long_outage
// preset, seed 2: 660 m, a 49 s GNSS outage over 360 m whose INS error
// grows to 3 m, a 3 m jump when GNSS returns, its sd flat; three of the
// five crossings seen inside it, none for 90 m after it), reconstructed
// and matched as the geometry sweep does (tests/support/geometry_sweep.h):
//   - the jump read by the control (adjustment/outage_model.h): the
//     crossings inside the outage, all correct, are kept as control, where
//     the jump taken as a step rejected them and left metres of error;
//   - with that reading switched off, the adjusted trajectory fits the
//     crossing after the outage worse than the input does: the guard
//     (adjustment/control_guard.h) keeps the input there, the result is no
//     worse than the input, and the report (pipeline/report.h, as
//     `zebrageo report` writes it) says so in report.json and report.html.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "pipeline/report_stage.h"
#include "simulator/simulated_survey.h"
#include "survey/survey.h"
#include "tests/support/geometry_sweep.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using support::GeometryRunResult;
using support::GeometrySweepOptions;
using support::RunGeometrySurvey;

constexpr uint64_t kSeed = 2;

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

GeometrySweepOptions LongOutageOptions(bool outage_readings) {
  GeometrySweepOptions options;
  options.preset = "long_outage";
  options.outage_readings = outage_readings;
  options.dump_images = false;
  return options;
}

class LongOutage : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ =
        new fs::path(fs::temp_directory_path() /
                     ("zebrageo_long_outage_" + std::to_string(::getpid())));
    fs::remove_all(*folder_);
    read_ = new GeometryRunResult(
        RunGeometrySurvey(kSeed, LongOutageOptions(true)));
    // The jump as a step: dumped (survey without images, the results and
    // adjustment.json) for `zebrageo report`.
    step_ = new GeometryRunResult(RunGeometrySurvey(
        kSeed, LongOutageOptions(false), (*folder_ / "step").string()));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*folder_);
    delete read_;
    delete step_;
    delete folder_;
  }
  static fs::path* folder_;
  static GeometryRunResult* read_;
  static GeometryRunResult* step_;
};
fs::path* LongOutage::folder_ = nullptr;
GeometryRunResult* LongOutage::read_ = nullptr;
GeometryRunResult* LongOutage::step_ = nullptr;

TEST_F(LongOutage, CorrectCrossingsInsideTheOutageAreKeptAsControl) {
  const GeometryRunResult& r = *read_;
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_TRUE(r.usable) << r.Line();
  EXPECT_EQ(r.wrong, 0) << r.Line();
  // Every crossing matched and none rejected by the adjustment: the three
  // inside the outage are control.
  EXPECT_EQ(r.crossings_matchable, 5) << r.Line();
  EXPECT_EQ(r.crossings_matched, 5) << r.Line();
  EXPECT_EQ(r.rejected_by_adjustment, 0) << r.Line();
  // Metres of error in the input, centimetres after.
  EXPECT_GT(r.h_before_m, 1.0) << r.Line();
  EXPECT_LT(r.h_after_m, 0.05) << r.Line();
  EXPECT_LT(r.v_after_m, 0.03) << r.Line();
  EXPECT_LE(r.att_after_deg, r.att_before_deg + 0.005) << r.Line();
  EXPECT_EQ(r.input_kept_stretches, 0) << r.Line();
  // The jump as a step (the model before issue 43) rejects some of them.
  EXPECT_GT(step_->rejected_by_adjustment, 0) << step_->Line();
  EXPECT_GT(step_->h_after_m, 5.0 * r.h_after_m) << step_->Line();
}

TEST_F(LongOutage, TheGuardKeepsTheInputWhereTheResultIsWorseAndSaysSo) {
  const GeometryRunResult& r = *step_;
  ASSERT_TRUE(r.error.empty()) << r.error;
  ASSERT_TRUE(r.usable) << r.Line();
  EXPECT_EQ(r.wrong, 0) << r.Line();
  EXPECT_GE(r.input_kept_stretches, 1) << r.Line();
  EXPECT_FALSE(r.worse_position) << r.Line();
  EXPECT_FALSE(r.worse_attitude) << r.Line();
  // Without the guard the same adjustment is worse after the outage.
  GeometrySweepOptions unguarded = LongOutageOptions(false);
  unguarded.guard = false;
  const GeometryRunResult u = RunGeometrySurvey(kSeed, unguarded);
  EXPECT_EQ(u.input_kept_stretches, 0);
  EXPECT_GT(u.h_after_m, r.h_after_m + 0.05) << u.Line();

  // The report of that run, as `zebrageo report` writes it, on the survey
  // as loaded from the dump (which has no images).
  const fs::path survey_folder = *folder_ / "step" / "survey";
  const fs::path results = *folder_ / "step" / "results";
  SimulationOptions simulation;
  simulation.seed = kSeed;
  ASSERT_EQ(ApplyPreset("long_outage", &simulation), "");
  simulation.render_images = false;
  const Survey survey = sim::ToSurvey(sim::MakeSimulatedSurvey(simulation),
                                      survey_folder.string());
  ReportInputs inputs;
  inputs.survey = &survey;
  inputs.results_folder = results.string();
  const nlohmann::json report = RunReportStage(inputs, ReportOptions());
  ASSERT_TRUE(fs::exists(results / "report.json"));
  const nlohmann::json& guard = report["adjustment"]["guard"];
  EXPECT_TRUE(guard["input_kept"].get<bool>());
  ASSERT_FALSE(guard["input_kept_stretches"].empty());
  const nlohmann::json& stretch = guard["input_kept_stretches"][0];
  EXPECT_FALSE(stretch["crossings"].empty());
  EXPECT_GT(stretch["adjusted_misfit_m"].get<double>(),
            stretch["input_misfit_m"].get<double>());
  int sentences = 0;
  for (const nlohmann::json& w : report["warnings"]) {
    const std::string text = w.get<std::string>();
    if (text.find("worse than the input trajectory does") !=
            std::string::npos &&
        text.find("the input trajectory is kept") != std::string::npos) {
      ++sentences;
    }
  }
  EXPECT_EQ(sentences, r.input_kept_stretches);
  const std::string html = ReadWholeFile((results / "report.html").string());
  EXPECT_NE(html.find("the input trajectory is kept"), std::string::npos);
  EXPECT_NE(html.find("Compared with the input trajectory"), std::string::npos);
}

}  // namespace
}  // namespace zebrageo
