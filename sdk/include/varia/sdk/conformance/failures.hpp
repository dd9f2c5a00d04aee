// The conformance suites' result: a list of failures, each one line saying what was claimed and
// what was measured. Empty means the plugin conforms. No test framework is needed to use them.
#pragma once

#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace varia::sdk::conformance {

class Failures {
 public:
  // Records a failure when `holds` is false; the parts are streamed into its message.
  template <class... Parts>
  void expect(bool holds, const Parts&... parts) {
    if (holds) return;
    std::ostringstream message;
    message << context_;
    (message << ... << parts);
    list_.push_back(message.str());
  }
  // Prefixed to the messages recorded from now on, e.g. "gauss-lobatto {\"points\": 3}: ".
  void set_context(std::string context) { context_ = std::move(context); }
  void append(const Failures& other) { list_.insert(list_.end(), other.list_.begin(), other.list_.end()); }

  bool empty() const { return list_.empty(); }
  const std::vector<std::string>& list() const { return list_; }

 private:
  std::string context_;
  std::vector<std::string> list_;
};

}  // namespace varia::sdk::conformance
