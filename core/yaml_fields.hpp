// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Reading YAML with messages that name the file, the line and the field (yaml-cpp marks).
// For the loaders' .cpp files: the one core header with yaml-cpp types, which core links
// privately — a target including it links yaml-cpp itself (tests/header_boundaries.cmake).

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/path_status.hpp"
#include "core/robot_model.hpp"
#include "core/text_encoding.hpp"

namespace mcopt::yaml {

/// "file:line: field: " for a node.
inline std::string where(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  const int line = node.Mark().line >= 0 ? node.Mark().line + 1 : 0;
  return file.string() + ":" + std::to_string(line) + ": " + field + ": ";
}

/// Runs `read`, a reader of `file`: what yaml-cpp throws on a node of a kind the reader did not
/// expect (a key that is a list, found by fuzzing: tests/fuzz/regressions/) becomes an
/// InputError at that node's line, never an internal error.
template <class Read>
auto reading(const std::filesystem::path& file, Read&& read) {
  try {
    return read();
  } catch (const YAML::Exception& e) {
    const int line = e.mark.is_null() ? 0 : e.mark.line + 1;
    throw InputError(file.string() + ":" + std::to_string(line) + ": " + (e.msg.empty() ? std::string("malformed YAML") : e.msg));
  }
}

inline YAML::Node loadFile(const std::filesystem::path& file) {
  if (!pathExists(file)) throw InputError(file.string() + ": file not found");
  // A folder named as a file makes the stream throw ios_base::failure (found by fuzzing).
  if (!isRegularFile(file)) throw InputError(file.string() + ": not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open (unreadable)");
  std::stringstream content;
  content << in.rdbuf();
  const std::string text = content.str();
  // yaml-cpp passes stray bytes of a UTF-8 file through to names, which JSON cannot hold
  // (text_encoding.hpp). A UTF-16/32 file starts with a byte-order mark or a zero byte
  // (YAML 1.2 §5.2) and yaml-cpp transcodes it itself.
  const bool wideEncoding = !text.empty() && (text[0] == '\0' || static_cast<unsigned char>(text[0]) == 0xFEu ||
                                              static_cast<unsigned char>(text[0]) == 0xFFu || (text.size() > 1 && text[1] == '\0'));
  if (const auto fault = wideEncoding ? std::nullopt : firstInvalidUtf8(text)) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", fault->byte);
    throw InputError(file.string() + ":" + std::to_string(fault->line) + ": not valid UTF-8 (byte " + hex + ")");
  }
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(file.string() + ":" + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
}

inline void rejectUnknownKeys(const std::filesystem::path& file, const YAML::Node& map, const std::string& field,
                              const std::vector<std::string>& allowed) {
  if (!map.IsMap()) throw InputError(where(file, map, field) + "expected a mapping");
  for (const auto& entry : map) {
    if (!entry.first.IsScalar()) throw InputError(where(file, entry.first, field) + "a key must be a name, not a list or mapping");
    const std::string key = entry.first.as<std::string>();
    bool known = false;
    std::string list;
    for (const std::string& name : allowed) {
      known = known || key == name;
      list += std::string(list.empty() ? "" : ", ") + name;
    }
    if (!known)
      throw InputError(where(file, entry.first, field.empty() ? key : field + "." + key) + "unknown key (expected one of " +
                       list + ")");
  }
}
inline void rejectUnknownKeys(const std::filesystem::path& file, const YAML::Node& map, const std::string& field,
                              std::initializer_list<const char*> allowed) {
  rejectUnknownKeys(file, map, field, std::vector<std::string>(allowed.begin(), allowed.end()));
}

/// A posture named in a motion or scenario file: `posture: NAME` and optional
/// `offsets: {joint: rad}` added to it. `file` and `field` locate `node` for errors
/// (unknown posture or joint); the caller checks which other keys `node` may hold.
/// (core/robot_files.cpp)
Eigen::VectorXd postureWithOffsets(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                                   const RobotModel& robot, const std::map<std::string, Eigen::VectorXd>& postures);

inline double number(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  double value = 0.0;
  try {
    if (!node.IsScalar()) throw YAML::Exception(node.Mark(), "not a scalar");
    value = node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(where(file, node, field) + "expected a number");
  }
  if (!std::isfinite(value)) throw InputError(where(file, node, field) + "must be finite, got " + node.as<std::string>());
  return value;
}

/// An integer from `minimum` to 1e7 (YAML's 3 or 3.0).
inline int integerAtLeast(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, int minimum) {
  const double value = number(file, node, field);
  if (value != std::floor(value) || value < minimum || value > 1e7)
    throw InputError(where(file, node, field) + "expected an integer ≥ " + std::to_string(minimum));
  return static_cast<int>(value);
}

/// true or false.
inline bool flag(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  try {
    if (!node.IsScalar()) throw YAML::Exception(node.Mark(), "not a scalar");
    return node.as<bool>();
  } catch (const YAML::Exception&) {
    throw InputError(where(file, node, field) + "expected true or false");
  }
}

inline double positive(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  const double value = number(file, node, field);
  if (value <= 0.0) throw InputError(where(file, node, field) + "must be positive, got " + std::to_string(value));
  return value;
}

inline double nonNegative(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  const double value = number(file, node, field);
  if (value < 0.0) throw InputError(where(file, node, field) + "must not be negative, got " + std::to_string(value));
  return value;
}

inline std::vector<double> numbers(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
                                   std::size_t count) {
  if (!node.IsSequence() || node.size() != count)
    throw InputError(where(file, node, field) + "expected a list of " + std::to_string(count) + " numbers");
  std::vector<double> values;
  for (std::size_t i = 0; i < count; ++i)
    values.push_back(number(file, node[i], field + "[" + std::to_string(i) + "]"));
  return values;
}

inline std::string text(const std::filesystem::path& file, const YAML::Node& node, const std::string& field) {
  if (!node.IsScalar()) throw InputError(where(file, node, field) + "expected a string");
  return node.as<std::string>();
}

inline const YAML::Node required(const std::filesystem::path& file, const YAML::Node& map, const char* key,
                                 const std::string& field) {
  const YAML::Node node = map[key];
  if (!node) throw InputError(where(file, map, field.empty() ? key : field + "." + key) + "missing required field");
  return node;
}

}  // namespace mcopt::yaml
