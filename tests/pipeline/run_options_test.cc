// RunOptions as JSON (pipeline/run_options.h): every field written and
// read back, members named by their path in every error.
#include "pipeline/run_options.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "pipeline/exit_codes.h"
#include "survey/option_json.h"

namespace zebrageo {
namespace {

using nlohmann::json;

// The message of the UsageError RunOptionsFromJson throws for `text`.
std::string ErrorOf(const std::string& text) {
  try {
    RunOptionsFromJson(json::parse(text));
  } catch (const UsageError& error) {
    return error.what();
  }
  return "";
}

// Every leaf of `j` (objects recursed), with its path.
void ForEachLeaf(json& j, const std::string& path,
                 const std::function<void(const std::string&, json&)>& f) {
  if (j.is_object()) {
    for (auto& [key, value] : j.items()) {
      ForEachLeaf(value, path.empty() ? key : path + "." + key, f);
    }
  } else {
    f(path, j);
  }
}

TEST(RunOptionsJson, TheDefaultsAreValidFiniteAndReadBackUnchanged) {
  json defaults = RunOptionsToJson(RunOptions());
  int leaves = 0;
  ForEachLeaf(defaults, "", [&](const std::string& path, json& value) {
    ++leaves;
    EXPECT_FALSE(value.is_null()) << path << " (a non-finite default)";
  });
  // Every stage's options: a few hundred fields.
  EXPECT_GT(leaves, 300);
  EXPECT_EQ(RunOptionsToJson(RunOptionsFromJson(defaults)), defaults);
  EXPECT_EQ(defaults["adjustment"]["model"]["knot_spacing_s"], 1.0);
  EXPECT_EQ(defaults["adjustment"]["solver"]["linear_solver"], "auto");
}

// Each field, changed in the JSON, comes back changed: every member the
// writer writes is one the reader reads into the same field.
TEST(RunOptionsJson, EveryFieldRoundTrips) {
  json changed = RunOptionsToJson(RunOptions());
  ForEachLeaf(changed, "", [](const std::string& path, json& value) {
    if (value.is_boolean()) {
      value = !value.get<bool>();
    } else if (value.is_number_unsigned()) {
      value = value.get<uint64_t>() + 1;
    } else if (value.is_number_integer()) {
      value = value.get<int64_t>() + 1;
    } else if (value.is_number()) {
      value = value.get<double>() * 1.5 + 0.25;
    } else if (path.find("linear_solver") != std::string::npos) {
      value = "SPARSE_SCHUR";
    } else if (value.is_string()) {
      value = value.get<std::string>() + "x";
    } else if (value.is_array()) {
      value[0] = value[0].get<double>() + 0.5;
    }
  });
  // Not checked: the changed values need not make sense together.
  const RunOptions read = OptionsFromJson<RunOptions>(changed);
  EXPECT_EQ(RunOptionsToJson(read), changed);
}

TEST(RunOptionsJson, AMemberLeftOutKeepsItsDefault) {
  const RunOptions options =
      RunOptionsFromJson(json::parse(R"({"adjustment": {"vehicle_motion":
                       {"sideslip_sigma_rad": 0.002}}, "rematch": false})"));
  EXPECT_EQ(options.adjustment.vehicle_motion.sideslip_sigma_rad, 0.002);
  EXPECT_FALSE(options.rematch);
  EXPECT_EQ(options.adjustment.model.knot_spacing_s,
            RunOptions().adjustment.model.knot_spacing_s);
  EXPECT_EQ(options.matching.max_drift_m, RunOptions().matching.max_drift_m);
}

TEST(RunOptionsJson, ErrorsNameTheMember) {
  EXPECT_NE(ErrorOf(R"({"adjustment": {"modle": {}}})")
                .find("adjustment.modle: not an option"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"matching": {"max_drift_m": "3"}})")
                .find("matching.max_drift_m: expected a number, got string"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"threads": 1.5})").find("threads: expected an integer"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"lines": 1})").find("lines: expected true or false"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"adjustment": {"solver": {"linear_solver": "QR"}}})")
                .find("adjustment.solver.linear_solver: expected one of auto, "
                      "DENSE_SCHUR"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"reconstruction": 3})")
                .find("reconstruction: expected an object of options"),
            std::string::npos);
  EXPECT_NE(ErrorOf("[]").find("the options: expected an object"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"reconstruction": {"threads": 3000000000}})")
                .find("reconstruction.threads: expected a smaller integer"),
            std::string::npos);
}

TEST(RunOptionsJson, ValuesAreCheckedAndNamedByTheirPath) {
  EXPECT_EQ(ErrorOf(R"({"adjustment": {"model": {"knot_spacing_s": -1}}})"),
            "adjustment.model.knot_spacing_s = -1: must be > 0");
  EXPECT_EQ(
      ErrorOf(
          R"({"reconstruction": {"rectification": {"ground_pixel_m": 0}}})"),
      "reconstruction.rectification.ground_pixel_m = 0: must be in (0, 0.2]");
  EXPECT_EQ(
      ErrorOf(R"({"adjustment": {"model": {"max_position_sigma_m": 0.01}}})"),
      "adjustment.model.max_position_sigma_m = 0.01: must be >= "
      "min_position_sigma_m (0.03)");
}

}  // namespace
}  // namespace zebrageo
