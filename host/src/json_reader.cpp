#include "json_reader.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdint>
#include <fstream>
#include <limits>
#include <set>
#include <vector>

#include "errors.hpp"

namespace varia::host {

using nlohmann::json;

namespace {

// The line and column (1-based) of a byte offset in a text.
std::pair<std::size_t, std::size_t> line_and_column(const std::string& text, std::size_t byte) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

// nlohmann's message without its "[json.exception...] parse error at line L, column C: " head.
std::string parse_error_reason(const std::string& what) {
  const auto column = what.find("column ");
  const auto colon = column == std::string::npos ? std::string::npos : what.find(": ", column);
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

// A JSON pointer for a message: "/" for the root, long ones cut after their first 120 characters.
std::string shown(const json::json_pointer& pointer) {
  constexpr std::size_t kMax = 120;
  const std::string text = pointer.empty() ? "/" : pointer.to_string();
  return text.size() <= kMax ? text : text.substr(0, kMax) + "...";
}

// A SAX pass over the text that builds nothing: it follows the JSON pointer of each value, and
// stops at the first syntax error, container nested deeper than kMaxJsonDepth or number outside
// the range of double (which nlohmann reports as a parse error without the pointer).
class Checker final : public json::json_sax_t {
 public:
  explicit Checker(const std::string& text) : text_(text) {}
  const std::string& error() const { return error_; }

  bool null() override { return scalar(); }
  bool boolean(bool) override { return scalar(); }
  bool number_integer(number_integer_t) override { return scalar(); }
  bool number_unsigned(number_unsigned_t) override { return scalar(); }
  bool number_float(number_float_t value, const string_t& text) override {
    enter();
    if (!std::isfinite(value)) return out_of_range(text);
    if (value != 0.0 && std::abs(value) < std::numeric_limits<double>::min())
      return fail(fmt::format("{}: expected 0 or a number of magnitude at least {:g} (below it a double loses "
                              "precision); found {}",
                              shown(pointer_), std::numeric_limits<double>::min(), text.substr(0, 40)));
    leave();
    return true;
  }
  bool string(string_t&) override { return scalar(); }
  bool binary(binary_t&) override { return scalar(); }
  bool start_object(std::size_t) override { return open(false); }
  bool key(string_t& name) override {
    pointer_.push_back(name);
    if (!frames_.back().keys.insert(name).second)
      return fail(fmt::format("{}: a repeated key; expected each key once in an object", shown(pointer_)));
    return true;
  }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(true); }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& e) override {
    constexpr int kNumberOverflow = 406;  // nlohmann's out_of_range.406: a number beyond double
    if (e.id == kNumberOverflow) {
      enter();
      return out_of_range(token);
    }
    const auto [line, column] = line_and_column(text_, position > 0 ? position - 1 : 0);
    return fail(fmt::format("invalid JSON at line {}, column {}: {}", line, column, parse_error_reason(e.what())));
  }

 private:
  struct Frame {
    bool array;
    std::size_t next_index = 0;
    std::set<std::string> keys;  // of an object, so far
  };

  // A value starts: in an array its index joins the pointer (in an object, key() added its name).
  void enter() {
    if (!frames_.empty() && frames_.back().array) pointer_.push_back(std::to_string(frames_.back().next_index++));
  }
  // A value ends: its token leaves the pointer.
  void leave() {
    if (!frames_.empty()) pointer_.pop_back();
  }
  bool scalar() {
    enter();
    leave();
    return true;
  }
  bool open(bool array) {
    enter();
    if (frames_.size() >= kMaxJsonDepth)
      return fail(fmt::format("{}: nested too deep; expected at most {} levels of objects and arrays",
                              shown(pointer_), kMaxJsonDepth));
    frames_.push_back(Frame{array, 0, {}});
    return true;
  }
  bool close() {
    frames_.pop_back();
    leave();
    return true;
  }
  bool out_of_range(const std::string& number) {
    return fail(fmt::format("{}: expected a number within the range of double (magnitude below 1.8e308); found {}",
                            shown(pointer_), number));
  }
  bool fail(std::string message) {
    error_ = std::move(message);
    return false;
  }

  const std::string& text_;
  std::vector<Frame> frames_;
  json::json_pointer pointer_;
  std::string error_;
};

std::string too_large() {
  return fmt::format("the file is larger than {} MiB; expected a scene of at most that size", kMaxJsonBytes >> 20);
}

// The whole file, refused once it passes kMaxJsonBytes (also for files whose size is not known
// beforehand, such as pipes).
std::string read_bounded(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(file, ec) && std::filesystem::file_size(file, ec) > kMaxJsonBytes && !ec)
    throw InputError(too_large());
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot be read: {}", std::strerror(errno)));
  std::string content;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    content.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (content.size() > kMaxJsonBytes) throw InputError(too_large());
  }
  if (in.bad()) throw InputError(fmt::format("cannot be read: {}", std::strerror(errno)));
  return content;
}

}  // namespace

json parse_json_text(const std::string& text) {
  // nlohmann ends its input at a NUL byte: what follows one would go unread.
  if (const auto nul = text.find('\0'); nul != std::string::npos) {
    const auto [line, column] = line_and_column(text, nul);
    throw InputError(fmt::format("invalid JSON at line {}, column {}: a NUL byte; expected JSON text", line, column));
  }
  Checker checker(text);
  if (!json::sax_parse(text, &checker) || !checker.error().empty()) throw InputError(checker.error().empty() ? "invalid JSON" : checker.error());
  // A number with a fraction part of zero (1.0) is an integer where the schemas ask for one.
  return json::parse(text, [](int, json::parse_event_t event, json& value) {
    if (event == json::parse_event_t::value && value.is_number_float()) {
      const double x = value.get<double>();
      constexpr double kExactIntegers = 9007199254740992.0;  // 2^53
      if (x == std::trunc(x) && std::abs(x) <= kExactIntegers && !(x == 0.0 && std::signbit(x)))
        value = static_cast<std::int64_t>(x);
    }
    return true;
  });
}

json read_json_file(const std::filesystem::path& file) { return parse_json_text(read_bounded(file)); }

}  // namespace varia::host
