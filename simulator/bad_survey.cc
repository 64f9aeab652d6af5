#include "simulator/bad_survey.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "survey/atomic_file.h"
#include "survey/text_file.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string ReadText(const fs::path& path) {
  return ReadTextFile(path.string(), path.string());
}

void WriteText(const fs::path& path, const std::string& text) {
  WriteFileAtomically(path.string(), [&text](std::ostream& out) {
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  });
}

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string JoinLines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  for (std::string field; std::getline(in, field, ',');) {
    fields.push_back(field);
  }
  return fields;
}

std::string JoinFields(const std::vector<std::string>& fields) {
  std::string line;
  for (size_t i = 0; i < fields.size(); ++i) {
    line += (i ? "," : "") + fields[i];
  }
  return line;
}

std::string Shortest(double value) {
  std::ostringstream text;
  text.precision(17);
  text << value;
  return text.str();
}

// Bytes that no image reader accepts (deterministic).
std::string Garbage(size_t size, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::string bytes(size, '\0');
  for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
  return bytes;
}

// The image files of exposures.csv, in file order.
std::vector<std::string> ImagePaths(const fs::path& folder) {
  std::vector<std::string> images;
  const std::vector<std::string> lines =
      SplitLines(ReadText(folder / "exposures.csv"));
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> fields = SplitFields(lines[i]);
    if (fields.size() >= 4) images.push_back(fields[3]);
  }
  return images;
}

// The trajectory cut in the middle of a data row, as by a copy that stopped
// part way: the last row has 5 fields, the last of them partial.
void TruncateTrajectory(const fs::path& folder) {
  const fs::path path = folder / "trajectory.csv";
  const std::string text = ReadText(path);
  size_t cut = text.find('\n', text.size() * 6 / 10) + 1;
  for (int commas = 0; commas < 4; ++cut) {
    if (text.at(cut) == ',') ++commas;
  }
  WriteText(path, text.substr(0, cut + 3));
}

// A height of "nan" in the middle of the trajectory.
void NanInTrajectory(const fs::path& folder) {
  const fs::path path = folder / "trajectory.csv";
  std::vector<std::string> lines = SplitLines(ReadText(path));
  std::vector<std::string> fields = SplitFields(lines.at(lines.size() / 2));
  fields.at(3) = "nan";
  lines[lines.size() / 2] = JoinFields(fields);
  WriteText(path, JoinLines(lines));
}

// The last 3 exposures an hour after the trajectory ends.
void ExposuresOutsideTrajectory(const fs::path& folder) {
  const fs::path path = folder / "exposures.csv";
  std::vector<std::string> lines = SplitLines(ReadText(path));
  std::set<std::string> ids;
  for (size_t i = lines.size() - 1; i >= 1 && ids.size() <= 3; --i) {
    std::vector<std::string> fields = SplitFields(lines[i]);
    ids.insert(fields.at(0));
    if (ids.size() > 3) break;
    fields.at(1) = Shortest(std::stod(fields.at(1)) + 3600.0);
    lines[i] = JoinFields(fields);
  }
  WriteText(path, JoinLines(lines));
}

// Edits the first line of rig.yaml that starts with `key` (the left
// camera's) with `edit`, given the text between '[' and ']'.
void EditRigLine(const fs::path& folder, const std::string& key,
                 const std::function<std::string(const std::string&)>& edit) {
  const fs::path path = folder / "rig.yaml";
  std::vector<std::string> lines = SplitLines(ReadText(path));
  for (std::string& line : lines) {
    const size_t at = line.find(key + ": [");
    if (at == std::string::npos) continue;
    const size_t open = line.find('[', at), close = line.rfind(']');
    line = line.substr(0, open + 1) +
           edit(line.substr(open + 1, close - open - 1)) + line.substr(close);
    break;
  }
  WriteText(path, JoinLines(lines));
}

std::string EditFirstNumber(const std::string& list,
                            const std::function<double(double)>& edit) {
  const size_t comma = list.find(',');
  return Shortest(edit(std::stod(list.substr(0, comma)))) + list.substr(comma);
}

// Keeps only the features of the crossings in `keep` (and the lines).
void FilterDatabase(const fs::path& folder,
                    const std::set<std::string>& remove) {
  json db = json::parse(ReadText(folder / "roadmarks.geojson"));
  json kept = json::array();
  for (const json& feature : db.at("features")) {
    const json& properties = feature.at("properties");
    if (properties.contains("crossing_id") &&
        properties["crossing_id"].is_string() &&
        remove.count(properties["crossing_id"].get<std::string>())) {
      continue;
    }
    kept.push_back(feature);
  }
  db["features"] = kept;
  WriteText(folder / "roadmarks.geojson", db.dump() + "\n");
}

// The database loses every crossing but the first two along the road: the
// rest of the drive (more than 150 m) has no control. Updates `meta`.
void DropAllButFirstTwoCrossings(const fs::path& folder, json* meta) {
  std::vector<double> s;
  for (const json& c : (*meta)["crossings"]) {
    if (c.value("in_street", false) && c.value("in_db", false)) {
      s.push_back(c["s_m"].get<double>());
    }
  }
  if (s.size() < 2) throw std::runtime_error("fewer than 2 crossings");
  std::sort(s.begin(), s.end());
  std::set<std::string> remove;
  for (json& c : (*meta)["crossings"]) {
    if (!c.value("in_db", false) || c["s_m"].get<double>() <= s[1]) continue;
    remove.insert(c["crossing_id"].get<std::string>());
    c["in_db"] = false;
  }
  FilterDatabase(folder, remove);
}

}  // namespace

const std::vector<BadSurveyKind>& BadSurveyKinds() {
  static const std::vector<BadSurveyKind> kinds = {
      {"truncated_trajectory", "error",
       "trajectory.csv cut in the middle of a row"},
      {"nan_trajectory", "error", "a height of nan in trajectory.csv"},
      {"garbage_images", "error",
       "every second image replaced by random bytes (more than 20% "
       "unreadable)"},
      {"missing_images", "error",
       "the images of every second exposure deleted (more than 20% missing)"},
      {"missing_rig", "error", "rig.yaml deleted"},
      {"exposures_outside", "error",
       "the last 3 exposures an hour after the trajectory ends"},
      {"bad_focal", "error", "a negative focal length in rig.yaml"},
      {"bad_rotation", "error",
       "a T_body_cam whose rotation is not orthonormal in rig.yaml"},
      {"bad_matrix", "error", "a K with 8 numbers in rig.yaml"},
      {"malformed_geojson", "error", "roadmarks.geojson cut half way"},
      {"empty_database", "warning",
       "roadmarks.geojson is a FeatureCollection without features"},
      {"no_zebra", "warning",
       "no zebra crossing painted in the street (the database has a stale "
       "one)"},
      {"unreadable_images", "warning",
       "two images unreadable: one random bytes, one truncated PNG"},
      {"no_control_stretch", "warning",
       "the database lacks every crossing but the first two: more than 150 m "
       "without control"},
  };
  return kinds;
}

const BadSurveyKind* FindBadSurveyKind(const std::string& name) {
  for (const BadSurveyKind& kind : BadSurveyKinds()) {
    if (kind.name == name) return &kind;
  }
  return nullptr;
}

std::string ApplyBadSurveySettings(const std::string& kind,
                                   SimulationOptions* options) {
  if (!FindBadSurveyKind(kind)) {
    std::string names;
    for (const BadSurveyKind& k : BadSurveyKinds()) names += " " + k.name;
    return "--bad " + kind + ": not a kind (kinds:" + names + ")";
  }
  // Small and fast: a short road, small images, few exposures. The fault,
  // not the survey, is under test.
  SimulationOptions& o = *options;
  o.road_length_m = 80.0;
  o.num_crossings = 2;
  o.num_stale_crossings = 0;
  o.num_missing_crossings = 0;
  o.num_missing_bands = 0;
  o.num_repainted_crossings = 0;
  o.min_crossing_spacing_m = 25.0;
  o.max_band_length_m = 4.5;
  o.image_width = 640;
  o.image_height = 480;
  o.focal_px = 560.0;
  o.supersampling = 2;
  o.exposure_spacing_m = 4.0;
  o.exposure_spacing_jitter_m = 0.5;
  if (kind == "no_zebra") {
    o.num_crossings = 0;
    o.num_stale_crossings = 1;
  } else if (kind == "no_control_stretch") {
    // Stratified crossings (one per 60 m slot after the first 25 m): the
    // first two are within 132 m of the start, so the drive after them has
    // > 150 m without control. Two, because the matcher may refuse a lone
    // crossing as ambiguous by one band period.
    o.road_length_m = 320.0;
    o.num_crossings = 5;
  }
  return "";
}

void BreakSurvey(const std::string& kind_name, const std::string& folder_name) {
  const BadSurveyKind* kind = FindBadSurveyKind(kind_name);
  if (!kind) throw std::invalid_argument("not a bad survey kind: " + kind_name);
  const fs::path folder(folder_name);
  const fs::path meta_path = folder / "truth" / "meta.json";
  json meta = json::parse(ReadText(meta_path));
  const std::vector<std::string> images = ImagePaths(folder);

  if (kind_name == "truncated_trajectory") {
    TruncateTrajectory(folder);
  } else if (kind_name == "nan_trajectory") {
    NanInTrajectory(folder);
  } else if (kind_name == "garbage_images") {
    for (size_t i = 0; i < images.size(); i += 2) {
      WriteText(folder / images[i], Garbage(4096, i));
    }
  } else if (kind_name == "missing_images") {
    // Rows of one exposure are consecutive pairs (left, right).
    for (size_t i = 0; i < images.size(); i += 4) {
      fs::remove(folder / images[i]);
      if (i + 1 < images.size()) fs::remove(folder / images[i + 1]);
    }
  } else if (kind_name == "missing_rig") {
    fs::remove(folder / "rig.yaml");
  } else if (kind_name == "exposures_outside") {
    ExposuresOutsideTrajectory(folder);
  } else if (kind_name == "bad_focal") {
    EditRigLine(folder, "K", [](const std::string& list) {
      return EditFirstNumber(list, [](double fx) { return -fx; });
    });
  } else if (kind_name == "bad_rotation") {
    EditRigLine(folder, "T_body_cam", [](const std::string& list) {
      return EditFirstNumber(list, [](double r11) { return r11 + 0.5; });
    });
  } else if (kind_name == "bad_matrix") {
    EditRigLine(folder, "K", [](const std::string& list) {
      return list.substr(0, list.rfind(','));
    });
  } else if (kind_name == "malformed_geojson") {
    const std::string text = ReadText(folder / "roadmarks.geojson");
    WriteText(folder / "roadmarks.geojson", text.substr(0, text.size() / 2));
  } else if (kind_name == "empty_database") {
    WriteText(folder / "roadmarks.geojson",
              "{\"type\": \"FeatureCollection\", \"features\": []}\n");
  } else if (kind_name == "unreadable_images") {
    WriteText(folder / images.at(4), Garbage(4096, 4));
    const std::string png = ReadText(folder / images.at(11));
    WriteText(folder / images.at(11), png.substr(0, png.size() / 2));
  } else if (kind_name == "no_control_stretch") {
    DropAllButFirstTwoCrossings(folder, &meta);
  }
  // no_zebra: the simulation itself is the fault.

  meta["bad"] = kind->name;
  meta["expect"] = kind->expect;
  meta["bad_description"] = kind->description;
  WriteText(meta_path, meta.dump(2) + "\n");
}

}  // namespace zebrageo
