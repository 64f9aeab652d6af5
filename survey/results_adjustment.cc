#include "survey/results_adjustment.h"

#include <cmath>
#include <limits>

#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/json_file.h"

namespace zebrageo {
namespace {

using nlohmann::json;

json Vector3Json(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

// Reads the fields of one JSON object, naming the file in errors. A number
// written as null (NaN, or a figure that was not computed) reads as NaN.
class Fields {
 public:
  Fields(const json& object, const std::string& display_name)
      : object_(object), name_(display_name) {
    if (!object_.is_object()) {
      throw InputError(name_, 0, "expected a JSON object");
    }
  }
  const json& At(const char* key) const {
    if (!object_.contains(key)) {
      throw InputError(name_, 0, std::string("no field '") + key + "'");
    }
    return object_.at(key);
  }
  Fields Object(const char* key) const { return Fields(At(key), name_); }
  template <typename T>
  T Get(const char* key) const {
    try {
      return At(key).get<T>();
    } catch (const json::exception& error) {
      throw InputError(name_, 0,
                       std::string("field '") + key + "': " + error.what());
    }
  }
  // A field added after the format's first version: `fallback` when an
  // older file lacks it.
  template <typename T>
  T GetOr(const char* key, T fallback) const {
    return object_.contains(key) ? Get<T>(key) : fallback;
  }
  double Number(const char* key) const {
    const json& value = At(key);
    if (value.is_null()) return std::numeric_limits<double>::quiet_NaN();
    return Get<double>(key);
  }
  template <int N>
  Eigen::Matrix<double, N, 1> Vector(const char* key) const {
    const json& value = At(key);
    if (!value.is_array() || value.size() != N) {
      throw InputError(name_, 0,
                       std::string("field '") + key + "': expected " +
                           std::to_string(N) + " numbers");
    }
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) {
      v[i] = value[i].is_null() ? std::numeric_limits<double>::quiet_NaN()
                                : value[i].get<double>();
    }
    return v;
  }
  const std::string& name() const { return name_; }

 private:
  const json& object_;
  const std::string& name_;
};

json CheckJson(const AdjustmentRecord::Check& c) {
  // No check point evaluated: null, so no one reads a perfect 0.
  const bool checked = c.evaluated_vertices > 0;
  auto figure = [checked](double value) {
    return checked ? json(value) : json(nullptr);
  };
  return {{"horizontal", figure(c.rmse_horizontal_m)},
          {"vertical", figure(c.rmse_vertical_m)},
          {"vertices", c.vertices},
          {"evaluated_vertices", c.evaluated_vertices},
          {"expected_from_database",
           {{"horizontal", figure(c.database_rms_horizontal_m)},
            {"vertical", figure(c.database_rms_vertical_m)}}},
          {"implied_trajectory",
           {{"horizontal", figure(c.implied_trajectory_horizontal_m)},
            {"vertical", figure(c.implied_trajectory_vertical_m)}}},
          {"note",
           "check residual = trajectory error + database error; "
           "implied_trajectory = sqrt(max(0, rmse^2 - "
           "expected_from_database^2)), for the adjustment made without the "
           "check crossings"},
          {"crossings", c.crossings},
          {"held_out_then_control", c.held_out_then_control}};
}

json ModelJson(const AdjustmentRecord::Model& m) {
  return {
      {"knot_spacing_s", m.knot_spacing_s},
      {"position_model_estimated", m.position_model_estimated},
      {"position_sigma_m", Vector3Json(m.position_sigma_m)},
      {"position_tau_s", Vector3Json(m.position_tau_s)},
      {"attitude_sigma_deg", Vector3Json(m.attitude_sigma_deg)},
      {"attitude_significance", Vector3Json(m.attitude_significance)},
      {"attitude_held", m.attitude_held},
      {"vehicle_motion_sigma_deg",
       {m.vehicle_motion_sigma_deg.x(), m.vehicle_motion_sigma_deg.y()}},
      {"tie_sigma_px", m.tie_sigma_px},
      {"vertex_sigma_px", m.vertex_sigma_px},
      {"crossing_offset_sigma_m", m.crossing_offset_sigma_m},
      {"check_crossing_share", m.check_crossing_share},
      {"blunder_threshold", m.blunder_threshold},
      {"self_calibrate_rig", m.self_calibrate_rig},
  };
}

AdjustmentRecord::Counts ReadCounts(const Fields& f) {
  AdjustmentRecord::Counts c;
  c.exposures = f.Get<int>("exposures");
  c.trajectory_samples = f.Get<int64_t>("trajectory_samples");
  c.knots = f.Get<int>("knots");
  c.control_vertices = f.Get<int>("control_vertices");
  c.check_vertices = f.Get<int>("check_vertices");
  c.rejected_vertices = f.Get<int>("rejected_vertices");
  c.control_crossings = f.Get<int>("control_crossings");
  c.check_crossings = f.Get<int>("check_crossings");
  c.tie_tracks = f.Get<int>("tie_tracks");
  c.residuals = f.Get<int>("residuals");
  c.reconstructed_vertices = f.Get<int64_t>("reconstructed_vertices");
  c.matches = f.Get<int64_t>("matches");
  return c;
}

AdjustmentRecord::Check ReadCheck(const Fields& f) {
  AdjustmentRecord::Check c;
  c.rmse_horizontal_m = f.Number("horizontal");
  c.rmse_vertical_m = f.Number("vertical");
  c.vertices = f.Get<int>("vertices");
  c.evaluated_vertices = f.Get<int>("evaluated_vertices");
  const Fields database = f.Object("expected_from_database");
  c.database_rms_horizontal_m = database.Number("horizontal");
  c.database_rms_vertical_m = database.Number("vertical");
  const Fields implied = f.Object("implied_trajectory");
  c.implied_trajectory_horizontal_m = implied.Number("horizontal");
  c.implied_trajectory_vertical_m = implied.Number("vertical");
  c.crossings = f.Get<int>("crossings");
  c.held_out_then_control = f.Get<bool>("held_out_then_control");
  return c;
}

AdjustmentRecord::Model ReadModel(const Fields& f) {
  AdjustmentRecord::Model m;
  m.knot_spacing_s = f.Number("knot_spacing_s");
  m.position_model_estimated = f.Get<bool>("position_model_estimated");
  m.position_sigma_m = f.Vector<3>("position_sigma_m");
  m.position_tau_s = f.Vector<3>("position_tau_s");
  m.attitude_sigma_deg = f.Vector<3>("attitude_sigma_deg");
  m.attitude_significance = f.Vector<3>("attitude_significance");
  m.attitude_held = f.Get<std::array<bool, 3>>("attitude_held");
  m.vehicle_motion_sigma_deg = f.Vector<2>("vehicle_motion_sigma_deg");
  m.tie_sigma_px = f.Number("tie_sigma_px");
  m.vertex_sigma_px = f.Number("vertex_sigma_px");
  m.crossing_offset_sigma_m = f.Number("crossing_offset_sigma_m");
  m.check_crossing_share = f.Number("check_crossing_share");
  m.blunder_threshold = f.Number("blunder_threshold");
  m.self_calibrate_rig = f.Get<bool>("self_calibrate_rig");
  return m;
}

// A time that may be open (null): NaN.
json TimeJson(double t) { return std::isfinite(t) ? json(t) : json(nullptr); }

json GuardJson(const AdjustmentRecord::Guard& g) {
  json crossings = json::array();
  for (const AdjustmentRecord::Guard::Crossing& c : g.crossings) {
    crossings.push_back({{"crossing_id", c.crossing_id},
                         {"used", c.used},
                         {"input_misfit_m", c.input_misfit_m},
                         {"adjusted_misfit_m", c.adjusted_misfit_m},
                         {"z", c.z},
                         {"worse", c.worse}});
  }
  json kept = json::array();
  for (const AdjustmentRecord::Guard::Stretch& s : g.input_kept) {
    kept.push_back({{"blend_begin_time_s", TimeJson(s.blend_begin_time_s)},
                    {"begin_time_s", TimeJson(s.begin_time_s)},
                    {"end_time_s", TimeJson(s.end_time_s)},
                    {"blend_end_time_s", TimeJson(s.blend_end_time_s)},
                    {"crossings", s.crossings},
                    {"input_misfit_m", s.input_misfit_m},
                    {"adjusted_misfit_m", s.adjusted_misfit_m}});
  }
  return {{"input_kept", !g.input_kept.empty()},
          {"note",
           "each matched crossing (used or rejected) placed with the input "
           "and with the adjusted trajectory; where the adjusted one is "
           "farther from the database beyond the database's own error, the "
           "input trajectory is kept (input_kept_stretches)"},
          {"input_kept_stretches", kept},
          {"crossings", crossings}};
}

AdjustmentRecord::Guard ReadGuard(const Fields& f) {
  AdjustmentRecord::Guard g;
  for (const json& value : f.At("crossings")) {
    const Fields c(value, f.name());
    g.crossings.push_back({c.Get<std::string>("crossing_id"),
                           c.Get<bool>("used"), c.Number("input_misfit_m"),
                           c.Number("adjusted_misfit_m"), c.Number("z"),
                           c.Get<bool>("worse")});
  }
  for (const json& value : f.At("input_kept_stretches")) {
    const Fields s(value, f.name());
    g.input_kept.push_back(
        {s.Number("blend_begin_time_s"), s.Number("begin_time_s"),
         s.Number("end_time_s"), s.Number("blend_end_time_s"),
         s.Get<std::vector<std::string>>("crossings"),
         s.Number("input_misfit_m"), s.Number("adjusted_misfit_m")});
  }
  return g;
}

AdjustmentRecord RecordOf(const Fields& f) {
  AdjustmentRecord r;
  r.usable = f.Get<bool>("usable");
  r.message = f.Get<std::string>("message");
  r.sigma0 = f.Number("sigma0");
  r.iterations = f.Get<int>("iterations");
  r.solves = f.Get<int>("solves");
  r.time_s = f.Number("time_s");
  r.counts = ReadCounts(f.Object("counts"));
  for (const auto& [type, value] : f.At("rms").items()) {
    const Fields rms(value, f.name());
    r.rms[type] = {rms.Get<std::string>("unit"), rms.Get<int>("count"),
                   rms.Number("before"), rms.Number("after")};
  }
  const Fields control = f.Object("control_rmse_m");
  r.control_rmse_horizontal_m = control.Number("horizontal");
  r.control_rmse_vertical_m = control.Number("vertical");
  r.check = ReadCheck(f.Object("check_rmse_m"));
  const Fields correction = f.Object("correction_m");
  r.max_correction_horizontal_m = correction.Number("max_horizontal");
  r.max_correction_vertical_m = correction.Number("max_vertical");
  r.rms_correction_horizontal_m = correction.Number("rms_horizontal");
  const Fields sd = f.Object("posterior_sd_m");
  r.posterior_sd_computed = sd.Get<bool>("computed");
  r.road_lines_only = f.GetOr<bool>("road_lines_only", false);
  r.median_posterior_sd_horizontal_m = sd.Number("median_horizontal");
  r.median_posterior_sd_vertical_m = sd.Number("median_vertical");
  for (const json& value : f.GetOr<json>("weakly_held_stretches", json())) {
    const Fields w(value, f.name());
    r.weakly_held.push_back({w.Get<std::string>("axis"),
                             w.Number("begin_time_s"), w.Number("end_time_s"),
                             w.Number("length_m"), w.Number("threshold_m"),
                             w.Number("max_sd_m"), w.Number("median_sd_m"),
                             w.Get<bool>("held_by_no_control")});
  }
  for (const json& value : f.At("rejected")) {
    const Fields p(value, f.name());
    r.rejected.push_back({p.Get<std::string>("crossing_id"), p.Get<int>("band"),
                          p.Get<int>("vertex"), p.Number("normalized_residual"),
                          p.Vector<3>("d_enu_m")});
  }
  for (const json& value : f.At("rig")) {
    const Fields c(value, f.name());
    r.rig.push_back({c.Get<std::string>("camera"), c.Vector<3>("lever_arm_m"),
                     c.Number("boresight_change_deg")});
  }
  r.model = ReadModel(f.Object("model"));
  if (f.GetOr<json>("guard", json()).is_object()) {
    r.guard = ReadGuard(f.Object("guard"));
  }
  if (f.At("warnings").is_array()) {
    r.warnings = f.Get<std::vector<std::string>>("warnings");
  }
  return r;
}

}  // namespace

json AdjustmentJson(const AdjustmentRecord& r) {
  json j;
  j["usable"] = r.usable;
  j["message"] = r.message;
  j["sigma0"] = r.sigma0;
  j["iterations"] = r.iterations;
  j["solves"] = r.solves;
  j["time_s"] = r.time_s;
  const AdjustmentRecord::Counts& c = r.counts;
  j["counts"] = {
      {"exposures", c.exposures},
      {"trajectory_samples", c.trajectory_samples},
      {"knots", c.knots},
      {"control_vertices", c.control_vertices},
      {"check_vertices", c.check_vertices},
      {"rejected_vertices", c.rejected_vertices},
      {"control_crossings", c.control_crossings},
      {"check_crossings", c.check_crossings},
      {"tie_tracks", c.tie_tracks},
      {"residuals", c.residuals},
      {"reconstructed_vertices", c.reconstructed_vertices},
      {"matches", c.matches},
  };
  json rms = json::object();
  for (const auto& [type, value] : r.rms) {
    rms[type] = {{"unit", value.unit},
                 {"count", value.count},
                 {"before", value.before},
                 {"after", value.after}};
  }
  j["rms"] = rms;
  j["control_rmse_m"] = {{"horizontal", r.control_rmse_horizontal_m},
                         {"vertical", r.control_rmse_vertical_m}};
  // Check points are held out: their RMSE is the honest accuracy figure. It
  // includes the database's own error (its sigma and per-crossing offset).
  j["check_rmse_m"] = CheckJson(r.check);
  j["correction_m"] = {{"max_horizontal", r.max_correction_horizontal_m},
                       {"max_vertical", r.max_correction_vertical_m},
                       {"rms_horizontal", r.rms_correction_horizontal_m}};
  j["road_lines_only"] = r.road_lines_only;
  j["posterior_sd_m"] = {
      {"computed", r.posterior_sd_computed},
      {"median_horizontal", r.median_posterior_sd_horizontal_m},
      {"median_vertical", r.median_posterior_sd_vertical_m}};
  json weak = json::array();
  for (const AdjustmentRecord::WeakStretch& w : r.weakly_held) {
    weak.push_back({{"axis", w.axis},
                    {"begin_time_s", w.begin_time_s},
                    {"end_time_s", w.end_time_s},
                    {"length_m", w.length_m},
                    {"threshold_m", w.threshold_m},
                    {"max_sd_m", w.max_sd_m},
                    {"median_sd_m", w.median_sd_m},
                    {"held_by_no_control", w.held_by_no_control}});
  }
  j["weakly_held_stretches"] = weak;
  json rejected = json::array();
  for (const AdjustmentRecord::Rejected& p : r.rejected) {
    rejected.push_back({{"crossing_id", p.crossing_id},
                        {"band", p.band},
                        {"vertex", p.vertex},
                        {"normalized_residual", p.normalized_residual},
                        {"d_enu_m", Vector3Json(p.d_enu_m)}});
  }
  j["rejected"] = rejected;
  json rig = json::array();
  for (const AdjustmentRecord::RigCamera& camera : r.rig) {
    rig.push_back({{"camera", camera.camera},
                   {"lever_arm_m", Vector3Json(camera.lever_arm_m)},
                   {"boresight_change_deg", camera.boresight_change_deg}});
  }
  j["rig"] = rig;
  j["model"] = ModelJson(r.model);
  j["guard"] = GuardJson(r.guard);
  if (r.tie_points) {
    const AdjustmentRecord::TiePoints& t = *r.tie_points;
    j["tie_points"] = {
        {"images_read", t.images_read},   {"images_missing", t.images_missing},
        {"matches", t.matches},           {"tracks", t.tracks},
        {"observations", t.observations}, {"time_s", t.time_s}};
  }
  j["warnings"] = r.warnings;
  return j;
}

void WriteAdjustmentRecord(const AdjustmentRecord& record,
                           const std::string& path) {
  const json j = AdjustmentJson(record);
  WriteFileAtomically(
      path, [&](std::ostream& stream) { stream << j.dump(2) << "\n"; });
}

AdjustmentRecord ReadAdjustmentRecord(const std::string& path,
                                      const std::string& display_name) {
  const json j = ReadJsonFile(path, display_name);
  const Fields fields(j, display_name);
  AdjustmentRecord record = RecordOf(fields);
  if (j.contains("tie_points")) {
    const Fields t = fields.Object("tie_points");
    record.tie_points = AdjustmentRecord::TiePoints{
        t.Get<int>("images_read"),  t.Get<int>("images_missing"),
        t.Get<int>("matches"),      t.Get<int>("tracks"),
        t.Get<int>("observations"), t.Number("time_s")};
  }
  return record;
}

}  // namespace zebrageo
