// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Bad input and misuse throw InputError with a message that names the file,
// line or field and what was expected (style.md, "two kinds of failure").
// Numerical outcomes (infeasible, iteration limit) are statuses, not exceptions.

#include <stdexcept>
#include <string>

namespace mcopt {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mcopt
