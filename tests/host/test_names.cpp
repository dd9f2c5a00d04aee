// ctest runs each doctest case by its name (doctest_discover_tests): a ';' in a name splits it into
// ctest tests that match no case and pass without running anything, and a ',' in a long case's
// name loses its "long" label. This keeps every name runnable.
#include <doctest/doctest.h>

#include <regex>

#include "support.hpp"

using namespace varia::test;

TEST_CASE("every test case name is runnable by ctest: no semicolon in a name") {
  const std::regex test_case(R"re(TEST_CASE\(((\s*"([^"\\]|\\.)*")+))re");
  const std::regex literal(R"re("(([^"\\]|\\.)*)")re");
  int names = 0;
  for (const auto& entry : fs::recursive_directory_iterator(kSourceDir / "tests")) {
    if (entry.path().extension() != ".cpp") continue;
    const std::string text = read_file(entry.path());
    for (std::sregex_iterator m(text.begin(), text.end(), test_case), end; m != end; ++m) {
      std::string name;
      const std::string literals = (*m)[1];
      for (std::sregex_iterator l(literals.begin(), literals.end(), literal); l != end; ++l) name += (*l)[1];
      CAPTURE(entry.path().string());
      CAPTURE(name);
      CHECK(name.find(';') == std::string::npos);
      ++names;
    }
  }
  CHECK(names > 200);
}
