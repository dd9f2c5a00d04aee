// Numbers in command-line text: the words of a flag's value (`ld --q0 1.3,2`, `ensemble --vary
// /p=list:1,2.5`), each a finite decimal number, read one way for every flag.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

namespace varia::host {

// The pieces of `text` between `separator`s (n separators give n + 1 pieces, empty ones kept).
inline std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::size_t from = 0;
  for (std::size_t at; (at = text.find(separator, from)) != std::string::npos; from = at + 1)
    parts.push_back(text.substr(from, at - from));
  parts.push_back(text.substr(from));
  return parts;
}

// The word as a finite number (strtod's syntax, all of it), or nothing.
inline std::optional<double> finite_number(const std::string& word) {
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(word.c_str(), &end);
  if (word.empty() || *end != '\0' || errno != 0 || !std::isfinite(x)) return std::nullopt;
  return x;
}

// "a,b,c" as finite numbers, or nothing when any piece is not one (an empty text or piece
// included).
inline std::optional<std::vector<double>> comma_separated_numbers(const std::string& text) {
  std::vector<double> values;
  for (const std::string& word : split(text, ',')) {
    const std::optional<double> x = finite_number(word);
    if (!x) return std::nullopt;
    values.push_back(*x);
  }
  return values;
}

}  // namespace varia::host
