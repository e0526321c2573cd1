#pragma once

#include <string>
#include <vector>

namespace tessera {

// "img2.jpg" < "img10.jpg": digit runs compare by value, the rest by character
// (case-insensitively, then exactly, so the order is total and deterministic).
bool NaturalLess(const std::string& a, const std::string& b);

std::string ToLower(std::string text);

// Splits on a single character; empty pieces are kept.
std::vector<std::string> Split(const std::string& text, char separator);

}  // namespace tessera
