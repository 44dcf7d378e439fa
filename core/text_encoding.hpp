// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Text read from robot files reaches result.json and the viewer as names (robot, links, joints),
// and JSON must be UTF-8: a name with a stray byte made the JSON writer throw after the run
// (found by fuzzing, tests/fuzz/regressions/robot_files/). Files are checked when read.

#include <cstddef>
#include <optional>
#include <string_view>

namespace mcopt {

/// Where `text` stops being valid UTF-8 (RFC 3629: no overlong forms, no surrogates, nothing
/// above U+10FFFF): the line (from 1) and the offending byte; nothing when it is all valid.
struct EncodingFault {
  std::size_t line = 1;
  unsigned char byte = 0;
};
std::optional<EncodingFault> firstInvalidUtf8(std::string_view text);

}  // namespace mcopt
