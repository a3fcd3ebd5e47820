#pragma once
// toml++ 3.3.0 (Debian 12's) reaches __builtin_unreachable, undefined behaviour, when it asks whether one of the
// code points U+00A1..U+0499 (accented Latin, Greek, Cyrillic), U+2C5E..U+2FFF, U+3001..U+3057 or U+FB26..U+FEFE
// is whitespace (marzer/tomlplusplus#295; tests/fuzz found it again). Where it asks depends on its error paths
// (a bare key, a value followed by a string, a backslash in a string, ...), so a file holding any of them is
// refused before toml++ sees it; inside strings they can be written as escapes (\u03C3).
#include <string>

namespace kushner {

/// InputError "path: line L, column C: ..." naming the first such code point of the UTF-8 `text`.
void check_toml_characters(const std::string& text, const std::string& path);

}  // namespace kushner
