// Reading JSON documents that come from users (spec: "Every non-zero exit prints one clear
// message"): bounded in size and nesting before a document is built, every number within the
// range of double, and every problem one InputError naming where it is: the line and column of a
// syntax error, the JSON pointer of a value out of range or nested too deep.
#pragma once

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace varia::host {

// Files larger than this are refused before they are read whole.
inline constexpr std::size_t kMaxJsonBytes = 16u << 20;  // 16 MiB
// Objects and arrays nested deeper than this are refused before the document is built.
inline constexpr std::size_t kMaxJsonDepth = 64;

// Parses a document (InputError). Messages do not name a file: the caller prefixes it.
nlohmann::json parse_json_text(const std::string& text);
// Reads and parses a file (InputError for an unreadable, oversized or invalid file).
nlohmann::json read_json_file(const std::filesystem::path& file);

}  // namespace varia::host
