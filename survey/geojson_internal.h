// Internal to survey/: GeoJSON helpers shared by roadmarks.cc and results.cc.
// Not part of the library's interface.
//
// nlohmann::json forgets where a value was in the text, but every error
// message must name a line. ParseJson turns a syntax error's byte offset into
// a line; FeatureLines scans the text once more (it is known to be valid
// JSON by then) and records the line on which each element of the root
// object's "features" array starts, so a bad feature can be named by line.
#ifndef ZEBRAGEO_SURVEY_GEOJSON_INTERNAL_H_
#define ZEBRAGEO_SURVEY_GEOJSON_INTERNAL_H_

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "survey/csv.h"
#include "survey/geodesy.h"
#include "survey/input_error.h"

namespace zebrageo {
namespace geojson_internal {

// 1-based line holding byte `offset` of `text`.
inline int LineAtByte(const std::string& text, size_t offset) {
  offset = std::min(offset, text.size());
  return 1 + static_cast<int>(std::count(
                 text.begin(), text.begin() + static_cast<long>(offset), '\n'));
}

// nlohmann's message without its "[json.exception.parse_error.101] " prefix.
inline std::string JsonProblem(const nlohmann::json::exception& e) {
  std::string what = e.what();
  const size_t bracket = what.find("] ");
  if (what.rfind("[json.exception", 0) == 0 && bracket != std::string::npos) {
    what = what.substr(bracket + 2);
  }
  return what;
}

// Parses `text`; a syntax error becomes InputError with its line.
inline nlohmann::json ParseJson(const std::string& text,
                                const std::string& display_name) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based, the position just after the offending character.
    throw InputError(display_name,
                     LineAtByte(text, e.byte > 0 ? e.byte - 1 : 0),
                     "malformed JSON: " + JsonProblem(e));
  } catch (const nlohmann::json::exception& e) {
    // A number too large for a double ("number overflow parsing '1e999'")
    // comes without a position: find the quoted token in the text.
    const std::string problem = JsonProblem(e);
    int line = 0;
    const size_t open = problem.find('\'');
    const size_t close = problem.rfind('\'');
    if (open != std::string::npos && close > open + 1) {
      const size_t at = text.find(problem.substr(open + 1, close - open - 1));
      if (at != std::string::npos) line = LineAtByte(text, at);
    }
    throw InputError(display_name, line, "malformed JSON: " + problem);
  }
}

// Line on which each element of the root object's "features" array starts,
// in order. `text` must be valid JSON.
inline std::vector<int> FeatureLines(const std::string& text) {
  struct Frame {
    bool object = false;
    bool expecting_key = false;    // objects: the next string is a key
    bool expecting_value = false;  // arrays: the next token starts an element
    bool features = false;         // the root object's "features" array
    std::string key;               // objects: the last key read
  };
  std::vector<Frame> stack;
  std::vector<int> lines;
  int line = 1;
  // nlohmann accepts a UTF-8 byte order mark; skip it too.
  size_t i = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  // Called at the first character of every value.
  auto value_starts = [&]() {
    if (!stack.empty() && !stack.back().object &&
        stack.back().expecting_value) {
      stack.back().expecting_value = false;
      if (stack.back().features) lines.push_back(line);
    }
  };
  while (i < text.size()) {
    const char c = text[i];
    switch (c) {
      case '\n':
        ++line;
        ++i;
        break;
      case ' ':
      case '\t':
      case '\r':
      case ':':
        ++i;
        break;
      case ',':
        if (!stack.empty()) {
          if (stack.back().object) {
            stack.back().expecting_key = true;
          } else {
            stack.back().expecting_value = true;
          }
        }
        ++i;
        break;
      case '{':
      case '[': {
        value_starts();
        Frame frame;
        frame.object = c == '{';
        frame.expecting_key = frame.object;
        frame.expecting_value = !frame.object;
        frame.features = !frame.object && stack.size() == 1 &&
                         stack.back().object && stack.back().key == "features";
        stack.push_back(frame);
        ++i;
        break;
      }
      case '}':
      case ']':
        if (!stack.empty()) stack.pop_back();
        ++i;
        break;
      case '"': {
        const size_t start = ++i;
        while (i < text.size() && text[i] != '"') {
          i += text[i] == '\\' ? 2 : 1;
        }
        const std::string raw = text.substr(start, i - start);
        ++i;
        if (!stack.empty() && stack.back().object &&
            stack.back().expecting_key) {
          stack.back().key = raw;
          stack.back().expecting_key = false;
        } else {
          value_starts();
        }
        break;
      }
      default:  // numbers, true, false, null
        value_starts();
        static constexpr char kEnds[] = ",:[]{}\" \t\r\n";
        while (i < text.size() &&
               std::memchr(kEnds, text[i], sizeof(kEnds) - 1) == nullptr) {
          ++i;
        }
        break;
    }
  }
  return lines;
}

// Checks the ranges of a [lon, lat, h] position read as numbers. Returns ""
// (and fills `geodetic`) or the problem. Shared by the readers of every JSON
// library used here, so that they accept and word the same.
inline std::string CheckPosition(const double (&values)[3],
                                 Geodetic* geodetic) {
  for (double value : values) {
    if (!std::isfinite(value)) return "holds a non-finite number";
  }
  if (values[0] < -180.0 || values[0] > 180.0) {
    return "longitude " + FormatDouble(values[0]) + " is outside [-180, 180]";
  }
  if (values[1] < -90.0 || values[1] > 90.0) {
    return "latitude " + FormatDouble(values[1]) + " is outside [-90, 90]";
  }
  geodetic->lon_deg = values[0];
  geodetic->lat_deg = values[1];
  geodetic->h_m = values[2];
  return "";
}

// The problem of a position array of `size` elements, "" when it is 3.
inline std::string PositionSizeProblem(size_t size) {
  if (size == 2) {
    return "has no height: [lon, lat] but heights are required ([lon, lat, "
           "h], ellipsoidal metres)";
  }
  if (size != 3) {
    return "has " + std::to_string(size) + " numbers; expected [lon, lat, h]";
  }
  return "";
}

// Reads one [lon, lat, h] position. Returns "" or the problem.
inline std::string ReadPosition(const nlohmann::json& position,
                                Geodetic* geodetic) {
  if (!position.is_array()) return "is not an array [lon, lat, h]";
  const std::string size_problem = PositionSizeProblem(position.size());
  if (!size_problem.empty()) return size_problem;
  double values[3];
  for (int k = 0; k < 3; ++k) {
    if (!position[k].is_number()) return "holds a value that is not a number";
    values[k] = position[k].get<double>();
  }
  return CheckPosition(values, geodetic);
}

// "[lon, lat, h]" with every digit, for writers. Throws std::invalid_argument
// on non-finite values: they would make the file unparsable.
inline std::string PositionText(const Geodetic& p) {
  if (!std::isfinite(p.lat_deg) || !std::isfinite(p.lon_deg) ||
      !std::isfinite(p.h_m)) {
    throw std::invalid_argument("GeoJSON writer: non-finite coordinate");
  }
  return "[" + FormatDouble(p.lon_deg) + ", " + FormatDouble(p.lat_deg) + ", " +
         FormatDouble(p.h_m) + "]";
}

// A JSON string literal (escaped).
inline std::string JsonString(const std::string& text) {
  return nlohmann::json(text).dump(-1, ' ', false,
                                   nlohmann::json::error_handler_t::replace);
}

}  // namespace geojson_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_GEOJSON_INTERNAL_H_
