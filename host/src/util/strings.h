#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace tessera {

// "img2.jpg" < "img10.jpg": digit runs compare by value, the rest by character
// (case-insensitively, then exactly, so the order is total and deterministic).
bool NaturalLess(const std::string& a, const std::string& b);

std::string ToLower(std::string text);

// Splits on a single character; empty pieces are kept.
std::vector<std::string> Split(const std::string& text, char separator);

// Text from outside (what a child program printed) fit for a one-line message: at most
// `max_chars` of it, each byte outside printable ASCII escaped (\n, \t, \xNN), and "...
// (N more bytes)" where it was cut.
std::string PrintableExcerpt(std::string_view text, size_t max_chars);

// The first line of `text` with text on it (leading blank space skipped), unbounded.
std::string_view FirstLine(std::string_view text);

// `text` as one file name of [A-Za-z0-9._-] (every other byte becomes '_'), at most
// `max_chars` long; never empty, "." or "..".
std::string SafeFileName(std::string_view text, size_t max_chars);

}  // namespace tessera
