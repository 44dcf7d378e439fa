// SPDX-License-Identifier: BSD-3-Clause
#include "core/text_encoding.hpp"

namespace mcopt {

std::optional<EncodingFault> firstInvalidUtf8(std::string_view text) {
  std::size_t line = 1;
  std::size_t i = 0;
  const std::size_t n = text.size();
  auto byteAt = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  auto isContinuation = [&](std::size_t k) { return k < n && (byteAt(k) & 0xC0u) == 0x80u; };
  while (i < n) {
    const unsigned char lead = byteAt(i);
    if (lead == '\n') ++line;
    if (lead < 0x80u) {
      ++i;
      continue;
    }
    // Length and the allowed range of the second byte (Table 3-7 of the Unicode standard).
    std::size_t length = 0;
    unsigned char low = 0x80u, high = 0xBFu;
    if (lead >= 0xC2u && lead <= 0xDFu) length = 2;
    else if (lead == 0xE0u) length = 3, low = 0xA0u;
    else if (lead >= 0xE1u && lead <= 0xECu) length = 3;
    else if (lead == 0xEDu) length = 3, high = 0x9Fu;
    else if (lead >= 0xEEu && lead <= 0xEFu) length = 3;
    else if (lead == 0xF0u) length = 4, low = 0x90u;
    else if (lead >= 0xF1u && lead <= 0xF3u) length = 4;
    else if (lead == 0xF4u) length = 4, high = 0x8Fu;
    if (length == 0) return EncodingFault{line, lead};
    if (i + 1 >= n || byteAt(i + 1) < low || byteAt(i + 1) > high) return EncodingFault{line, i + 1 < n ? byteAt(i + 1) : lead};
    for (std::size_t k = 2; k < length; ++k)
      if (!isContinuation(i + k)) return EncodingFault{line, i + k < n ? byteAt(i + k) : lead};
    i += length;
  }
  return std::nullopt;
}

}  // namespace mcopt
