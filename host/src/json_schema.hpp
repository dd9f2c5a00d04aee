// JSON Schema (draft-07) validation with one-line messages (spec: "Every non-zero exit prints one
// clear message ... the JSON pointer of a bad scene field and what was expected").
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace varia::host {

class SchemaValidator {
 public:
  // Throws std::invalid_argument when `schema` is not a schema valijson can read.
  explicit SchemaValidator(nlohmann::json schema);
  ~SchemaValidator();
  SchemaValidator(SchemaValidator&&) noexcept;

  // Throws InputError "<prefix><pointer>: <what was wrong>; expected <what>" for the most specific
  // violation. `prefix` is the JSON pointer of `instance` in the scene ("" for the scene itself).
  void validate(const nlohmann::json& instance, const std::string& prefix) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Throws std::invalid_argument when a plugin's parameter schema uses what the host does not give
// valijson: references ($ref, $id) and regular expressions (pattern, patternProperties, format).
void check_parameter_schema(const nlohmann::json& schema);

// A short rendering of a JSON value for messages ("found ...").
std::string brief(const nlohmann::json& value);

}  // namespace varia::host
