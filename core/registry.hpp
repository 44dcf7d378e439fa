// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the registries by name share (inner solvers, contact models, contact-force
// formulations): the names of their entries in the registry's order, and the entry of a name.
// An entry is any type with a `name` member.
#include <string>
#include <vector>

namespace mcopt {

template <class Entry>
std::vector<std::string> registryNames(const std::vector<Entry>& entries) {
  std::vector<std::string> names;
  names.reserve(entries.size());
  for (const Entry& e : entries) names.push_back(e.name);
  return names;
}

/// The entry of that name, or null.
template <class Entry>
const Entry* findInRegistry(const std::vector<Entry>& entries, const std::string& name) {
  for (const Entry& e : entries)
    if (e.name == name) return &e;
  return nullptr;
}

}  // namespace mcopt
