// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// JSON reading for the command's input files: every error names the file and the field.

#include <Eigen/Core>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>

#include "core/errors.hpp"
#include "core/path_status.hpp"

namespace mcopt::json_io {

using Json = nlohmann::json;

inline Json readFile(const std::filesystem::path& path) {
  if (pathExists(path) && !isRegularFile(path)) throw InputError(path.string() + ": not a file");
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open (missing or unreadable)");
  try {
    return Json::parse(in);
  } catch (const Json::exception& e) {
    // parse_error, and out_of_range for a number beyond a double (1e99999: found by fuzzing,
    // tests/fuzz/regressions/).
    throw InputError(path.string() + ": malformed JSON: " + e.what());
  }
}

/// A list of `count` finite numbers (count < 0: any length).
inline Eigen::VectorXd numbers(const std::filesystem::path& file, const Json& node, const std::string& field,
                               long count = -1) {
  if (!node.is_array() || (count >= 0 && static_cast<long>(node.size()) != count))
    throw InputError(file.string() + ": " + field + ": expected a list of " +
                     (count >= 0 ? std::to_string(count) + " " : "") + "numbers" +
                     (node.is_array() ? ", got " + std::to_string(node.size()) : ""));
  Eigen::VectorXd v(static_cast<Eigen::Index>(node.size()));
  for (std::size_t i = 0; i < node.size(); ++i) {
    if (!node[i].is_number())
      throw InputError(file.string() + ": " + field + "[" + std::to_string(i) + "]: expected a number");
    v[static_cast<Eigen::Index>(i)] = node[i].get<double>();
    if (!std::isfinite(v[static_cast<Eigen::Index>(i)]))
      throw InputError(file.string() + ": " + field + "[" + std::to_string(i) + "]: not a finite number");
  }
  return v;
}

/// Refuses keys of `node` (an object) that are not in `keys`, naming the field.
inline void allowKeys(const std::filesystem::path& file, const Json& node, const std::string& field,
               std::initializer_list<const char*> keys) {
  if (!node.is_object()) throw InputError(file.string() + ": " + field + ": expected an object");
  for (const auto& [key, value] : node.items()) {
    bool known = false;
    for (const char* k : keys) known |= key == k;
    if (known) continue;
    std::string list;
    for (const char* k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
    throw InputError(file.string() + ": " + field + "." + key + ": unknown key (expected " + list + ")");
  }
}

/// The member `key` of `node`, or an error naming the field.
inline const Json& required(const std::filesystem::path& file, const Json& node, const std::string& field, const char* key) {
  if (!node.contains(key)) throw InputError(file.string() + ": " + field + ": missing '" + key + "'");
  return node[key];
}

inline Json toJson(const Eigen::Ref<const Eigen::VectorXd>& v) {
  Json a = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

/// Row-major nested arrays.
inline Json matrixToJson(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  Json rows = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace mcopt::json_io
