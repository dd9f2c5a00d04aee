// The one table of constructions: adding a construction is adding its file to this folder and its
// line here.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "../errors.hpp"
#include "../json_schema.hpp"
#include "construction.hpp"

namespace varia::host {

const Construction& galerkin_construction();
const Construction& shooting_construction();
const Construction& one_step_construction();
const Construction& lie_verlet_construction();

namespace {

const std::vector<const Construction*>& table() {
  static const std::vector<const Construction*> constructions{&galerkin_construction(), &shooting_construction(),
                                                              &one_step_construction(), &lie_verlet_construction()};
  return constructions;
}

}  // namespace

std::vector<std::string> construction_names() {
  std::vector<std::string> names;
  for (const Construction* c : table()) names.emplace_back(c->name());
  return names;
}

std::string constructions_taking_forces() {
  std::vector<std::string> names;
  for (const Construction* c : table())
    if (c->takes_forces()) names.push_back(fmt::format("'{}'", c->name()));
  if (names.size() < 2) return fmt::format("{}", fmt::join(names, ""));
  return fmt::format("{} and {}", fmt::join(names.begin(), names.end() - 1, ", "), names.back());
}

const Construction& construction_named(const std::string& name) {
  for (const Construction* c : table())
    if (name == c->name()) return *c;
  std::vector<std::string> quoted;
  for (const std::string& known : construction_names()) quoted.push_back('"' + known + '"');
  throw InputError(fmt::format("/method/construction: expected one of {}; found {}", fmt::join(quoted, ", "),
                               brief(nlohmann::json(name))));
}

}  // namespace varia::host
