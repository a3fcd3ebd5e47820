#include "drivers/toml_characters.hpp"

#include "core/errors.hpp"

#include <cstdio>

namespace kushner {

namespace {

/// The ranges of drivers/toml_characters.hpp: where toml++ 3.3.0's is_non_ascii_horizontal_whitespace() falls to
/// its unreachable default.
bool mishandled(char32_t c) {
  return (c >= 0xA1 && c <= 0x499) || (c >= 0x2C5E && c <= 0x2FFF) || (c >= 0x3001 && c <= 0x3057) ||
         (c >= 0xFB26 && c <= 0xFEFE);
}

}  // namespace

void check_toml_characters(const std::string& text, const std::string& path) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < text.size(); ++column) {
    const unsigned char lead = static_cast<unsigned char>(text[i]);
    if (lead == '\n') {
      ++line;
      column = 0;
    }
    // Decode one UTF-8 sequence; a malformed one is left for toml++ to report (it stops there).
    const int length = lead < 0xC0 ? 1 : lead < 0xE0 ? 2 : lead < 0xF0 ? 3 : 4;
    char32_t c = length == 1 ? lead : lead & (0x3F >> (length - 1));
    for (int k = 1; k < length && i + k < text.size(); ++k)
      c = (c << 6) | (static_cast<unsigned char>(text[i + k]) & 0x3F);
    if (length > 1 && mishandled(c)) {
      char code[16];
      std::snprintf(code, sizeof code, "U+%04X", static_cast<unsigned>(c));
      throw InputError(path + ": line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + code +
                       " is a character the TOML reader of this build (toml++ 3.3.0) mishandles; write it as \\u" +
                       (code + 2) + " inside a string, or leave it out");
    }
    i += length;
  }
}

}  // namespace kushner
