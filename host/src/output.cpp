#include "output.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

#include <fmt/ranges.h>

#include "errors.hpp"

namespace varia::host {

namespace {
constexpr std::size_t kFlushBytes = 1 << 16;  // write to the file in chunks of whole rows
}

CsvWriter::CsvWriter(const std::filesystem::path& file) {
  if (file == "-") {
    file_ = stdout;
    return;
  }
  file_ = std::fopen(file.c_str(), "wb");
  if (file_ == nullptr)
    throw InputError(fmt::format("--out {}: cannot be written: {}", file.string(), std::strerror(errno)));
  owned_ = true;
}

CsvWriter::~CsvWriter() {
  flush();
  if (owned_) std::fclose(file_);
}

void CsvWriter::header(const std::vector<std::string>& columns) {
  fmt::format_to(std::back_inserter(buffer_), "{}", fmt::join(columns, ","));
  end_row();
}

void CsvWriter::row(double t, const double* a, int na, const double* b, int nb,
                    const std::vector<double>& rest) {
  auto out = std::back_inserter(buffer_);
  fmt::format_to(out, "{}", t);
  for (int i = 0; i < na; ++i) fmt::format_to(out, ",{}", a[i]);
  for (int i = 0; i < nb; ++i) fmt::format_to(out, ",{}", b[i]);
  for (double value : rest) fmt::format_to(out, ",{}", value);
  end_row();
}

void CsvWriter::end_row() {
  buffer_.push_back('\n');
  if (buffer_.size() >= kFlushBytes) flush();
}

void CsvWriter::flush() {
  if (buffer_.size() > 0) std::fwrite(buffer_.data(), 1, buffer_.size(), file_);
  buffer_.clear();
  std::fflush(file_);
}

void write_json_file(const std::filesystem::path& file, const nlohmann::ordered_json& document) {
  const std::string text = document.dump(2) + "\n";
  if (file == "-") {
    std::fwrite(text.data(), 1, text.size(), stdout);
    return;
  }
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw InputError(fmt::format("{}: cannot be written: {}", file.string(), std::strerror(errno)));
}

}  // namespace varia::host
