// A manifold of a structure no construction serves: the unit sphere S2 in R^3 declared as a
// homogeneous space (of SO(3)), with a retraction by normalization, but without its equation
// (Manifold::defining_constraint, which the bundled S2 gives). The host must refuse a scene on
// it once, at /system/manifold, whatever the construction (exit 2), not take it for a Lie group.
#include <cmath>
#include <cstdio>

#include <varia/abi/manifold.hpp>
#include <varia/sdk/no_parameters.hpp>
#include <varia/sdk/plugin.hpp>

namespace {

class UnservedSphere final : public varia::Manifold {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"json({"structure": "homogeneous space", "fault": "none (tests only)"})json";

  UnservedSphere(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "unserved-sphere");
  }
  int point_size() const noexcept override { return 3; }
  int dim() const noexcept override { return 2; }
  varia::ManifoldStructure structure() const noexcept override { return varia::ManifoldStructure::homogeneous_space; }
  // q0 + xi along a tangent basis of q0, normalized (a retraction, not the natural chart).
  varia::Status retract(const double* q0, const double* xi, double* q) noexcept override {
    double e1[3], e2[3];
    tangent_basis(q0, e1, e2);
    double norm = 0.0;
    for (int i = 0; i < 3; ++i) q[i] = q0[i] + xi[0] * e1[i] + xi[1] * e2[i], norm += q[i] * q[i];
    for (int i = 0; i < 3; ++i) q[i] /= std::sqrt(norm);
    return nullptr;
  }
  varia::Status local(const double* q0, const double* q, double* xi) noexcept override {
    double e1[3], e2[3];
    tangent_basis(q0, e1, e2);
    xi[0] = xi[1] = 0.0;
    for (int i = 0; i < 3; ++i) xi[0] += (q[i] - q0[i]) * e1[i], xi[1] += (q[i] - q0[i]) * e2[i];
    return nullptr;
  }
  bool contains(const double* q, char* why, int why_size) noexcept override {
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    if (std::abs(norm - 1.0) <= 1e-12) return true;
    std::snprintf(why, static_cast<std::size_t>(why_size), "|q| = %.17g, not 1", norm);
    return false;
  }

 private:
  // Two unit vectors orthogonal to q0 and to each other.
  static void tangent_basis(const double* q0, double* e1, double* e2) {
    const double a[3] = {std::abs(q0[0]) < 0.9 ? 1.0 : 0.0, std::abs(q0[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    const double along = a[0] * q0[0] + a[1] * q0[1];
    double norm = 0.0;
    for (int i = 0; i < 3; ++i) e1[i] = a[i] - along * q0[i], norm += e1[i] * e1[i];
    for (int i = 0; i < 3; ++i) e1[i] /= std::sqrt(norm);
    e2[0] = q0[1] * e1[2] - q0[2] * e1[1];
    e2[1] = q0[2] * e1[0] - q0[0] * e1[2];
    e2[2] = q0[0] * e1[1] - q0[1] * e1[0];
  }
};

}  // namespace

VARIA_PLUGIN(UnservedSphere, manifold, unserved_sphere)
