// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Bad input and misuse throw InputError with a message that names the file,
// line or field and what was expected (style.md, "two kinds of failure").
// Numerical outcomes (infeasible, iteration limit) are statuses, not exceptions.

#include <stdexcept>
#include <string>
#include <vector>

namespace mcopt {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Names for a message or a help text: "a, b or c" (a registry's entries, in their order).
inline std::string alternatives(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}

}  // namespace mcopt
