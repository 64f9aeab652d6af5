// Options as data: an options struct lists its fields once,
//
//   template <typename Visitor>
//   void VisitFields(Visitor& v) {
//     v("knot_spacing_s", knot_spacing_s);   // bool, integer, double, string
//     v("solver", solver);                   // a nested options struct
//     v("linear_solver", linear_solver, kLinearSolverNames);  // an enum
//   }
//
// and these turn it into JSON and back: one object per struct, one member
// per field under the field's own name, nested structs as nested objects.
// Reading starts from the struct's defaults: a member left out keeps its
// default; an unknown member, or one of the wrong type, is an error naming
// it by its path ("adjustment.model.knot_spacing_s: ..."). Doubles are
// written exactly (nlohmann prints the shortest representation that reads
// back to the same double).
#ifndef ZEBRAGEO_SURVEY_OPTION_JSON_H_
#define ZEBRAGEO_SURVEY_OPTION_JSON_H_

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace zebrageo {

// An options document that does not fit the options: what() names the
// member by its path and says what is wrong.
class OptionsJsonError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The names of an enum's values, as options files spell them.
template <typename Enum>
using OptionEnumNames = std::vector<std::pair<Enum, const char*>>;

namespace option_json_internal {

// Whether T lists its fields (VisitFields).
struct ProbeVisitor {
  template <typename... Args>
  void operator()(Args&&...) {}
};
template <typename T, typename = void>
struct HasFields : std::false_type {};
template <typename T>
struct HasFields<T, std::void_t<decltype(std::declval<T&>().VisitFields(
                        std::declval<ProbeVisitor&>()))>> : std::true_type {};

std::string Describe(const nlohmann::json& value);

}  // namespace option_json_internal

// Writes every field of a struct into `json` (an object).
class OptionsJsonWriter {
 public:
  explicit OptionsJsonWriter(nlohmann::json* json) : json_(json) {}

  template <typename T>
  void operator()(const char* name, T& value) {
    if constexpr (option_json_internal::HasFields<T>::value) {
      nlohmann::json nested = nlohmann::json::object();
      OptionsJsonWriter writer(&nested);
      value.VisitFields(writer);
      (*json_)[name] = std::move(nested);
    } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
      (*json_)[name] = {value.x(), value.y(), value.z()};
    } else {
      (*json_)[name] = value;
    }
  }
  template <typename Enum>
  void operator()(const char* name, Enum& value,
                  const OptionEnumNames<Enum>& names) {
    for (const auto& [v, text] : names) {
      if (v == value) (*json_)[name] = text;
    }
  }

 private:
  nlohmann::json* json_;
};

// Reads the members of `json` (an object) into a struct's fields.
class OptionsJsonReader {
 public:
  // `path`: the object's own path ("" at the top), for messages.
  OptionsJsonReader(const nlohmann::json& json, std::string path)
      : json_(json), path_(std::move(path)) {}

  template <typename T>
  void operator()(const char* name, T& value) {
    const nlohmann::json* member = Member(name);
    if (member == nullptr) return;
    const std::string key = Key(name);
    if constexpr (option_json_internal::HasFields<T>::value) {
      Read(*member, key, &value);
    } else if constexpr (std::is_same_v<T, bool>) {
      Expect(member->is_boolean(), key, *member, "true or false");
      value = member->get<bool>();
    } else if constexpr (std::is_integral_v<T>) {
      Expect(member->is_number_integer(), key, *member, "an integer");
      if (member->is_number_unsigned()) {
        const uint64_t u = member->get<uint64_t>();
        Expect(u <= static_cast<uint64_t>(std::numeric_limits<T>::max()), key,
               *member, "a smaller integer");
        value = static_cast<T>(u);
      } else {
        const int64_t i = member->get<int64_t>();
        Expect(i >= static_cast<int64_t>(std::numeric_limits<T>::min()) &&
                   (i < 0 ||
                    static_cast<uint64_t>(i) <=
                        static_cast<uint64_t>(std::numeric_limits<T>::max())),
               key, *member, "an integer in the field's range");
        value = static_cast<T>(i);
      }
    } else if constexpr (std::is_floating_point_v<T>) {
      Expect(member->is_number(), key, *member, "a number");
      value = member->get<T>();
    } else if constexpr (std::is_same_v<T, std::string>) {
      Expect(member->is_string(), key, *member, "a string");
      value = member->get<std::string>();
    } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
      Expect(member->is_array() && member->size() == 3 &&
                 (*member)[0].is_number() && (*member)[1].is_number() &&
                 (*member)[2].is_number(),
             key, *member, "an array of 3 numbers");
      value = Eigen::Vector3d((*member)[0].get<double>(),
                              (*member)[1].get<double>(),
                              (*member)[2].get<double>());
    } else {
      static_assert(std::is_same_v<T, std::vector<double>>,
                    "an option of a type options files do not hold");
      Expect(member->is_array(), key, *member, "an array of numbers");
      value.clear();
      for (const nlohmann::json& item : *member) {
        Expect(item.is_number(), key, *member, "an array of numbers");
        value.push_back(item.get<double>());
      }
    }
  }
  template <typename Enum>
  void operator()(const char* name, Enum& value,
                  const OptionEnumNames<Enum>& names) {
    const nlohmann::json* member = Member(name);
    if (member == nullptr) return;
    std::string known;
    for (const auto& [v, text] : names) {
      if (member->is_string() && member->get<std::string>() == text) {
        value = v;
        return;
      }
      known += std::string(known.empty() ? "" : ", ") + text;
    }
    Expect(false, Key(name), *member, "one of " + known);
  }

  // Reads `json` into *options (its fields as they are are the defaults).
  // Throws OptionsJsonError for a member of the wrong type or one `options`
  // does not have.
  template <typename Options>
  static void Read(const nlohmann::json& json, const std::string& path,
                   Options* options) {
    if (!json.is_object()) {
      throw OptionsJsonError(
          (path.empty() ? std::string("the options") : path) +
          ": expected an object of options, got " +
          option_json_internal::Describe(json));
    }
    OptionsJsonReader reader(json, path);
    options->VisitFields(reader);
    reader.RefuseUnknownMembers();
  }

 private:
  const nlohmann::json* Member(const char* name) {
    known_.insert(name);
    const auto it = json_.find(name);
    return it == json_.end() ? nullptr : &*it;
  }
  std::string Key(const std::string& name) const {
    return path_.empty() ? name : path_ + "." + name;
  }
  static void Expect(bool holds, const std::string& key,
                     const nlohmann::json& value, const std::string& what) {
    if (!holds) {
      throw OptionsJsonError(key + ": expected " + what + ", got " +
                             option_json_internal::Describe(value));
    }
  }
  void RefuseUnknownMembers() const;

  const nlohmann::json& json_;
  std::string path_;
  std::set<std::string> known_;
};

// The options as JSON (by value: VisitFields is not const).
template <typename Options>
nlohmann::json OptionsToJson(Options options) {
  nlohmann::json json = nlohmann::json::object();
  OptionsJsonWriter writer(&json);
  options.VisitFields(writer);
  return json;
}

// `defaults` with the members of `json` applied. Throws OptionsJsonError.
template <typename Options>
Options OptionsFromJson(const nlohmann::json& json, Options defaults = {}) {
  OptionsJsonReader::Read(json, "", &defaults);
  return defaults;
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_OPTION_JSON_H_
