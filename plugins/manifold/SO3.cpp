// SO(3), the rotation group, as a manifold (varia/core/so3.hpp has the mathematics). A point is a
// rotation matrix R, 9 numbers, row-major; tangent vectors, velocities and momenta are
// left-trivialized, 3 numbers (Rdot = R hat(Omega)). The natural chart at R0 (paper, sec. 2,
// "Natural charts": psi_{R0}^{-1}(xi) = R0 exp(xi), psi_{R0}(R) = log(R0^T R)) is
//   retract: R = R0 exp(hat xi) (Rodrigues),   local: xi = log(R0^T R), |xi| <= pi.
#include <Eigen/LU>
#include <cmath>
#include <cstdio>

#include "varia/core/manifold.hpp"
#include "varia/core/so3.hpp"
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

using varia::so3::from_row_major;
using varia::so3::to_row_major;

// A point is accepted when ||I - R^T R||_F and |det R - 1| are below this.
constexpr double kMembershipTolerance = 1e-9;

class SO3 final : public varia::Manifold {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"json({
    "group": "SO(3) (left multiplication)",
    "chart": "natural: R0 exp(xi), exp by Rodrigues' formula",
    "point": "rotation matrix, 9 numbers, row-major",
    "tangent": "left-trivialized, 3 numbers"
  })json";

  SO3(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "SO3");
  }

  int point_size() const noexcept override { return 9; }
  int dim() const noexcept override { return 3; }
  bool is_vector_space() const noexcept override { return false; }

  varia::Status retract(const double* q0, const double* xi, double* q) noexcept override {
    const Eigen::Vector3d w(xi[0], xi[1], xi[2]);
    to_row_major(from_row_major(q0) * varia::so3::exp(w), q);
    return nullptr;
  }

  varia::Status local(const double* q0, const double* q, double* xi) noexcept override {
    varia::so3::chart_local(q0, q, xi);
    return nullptr;
  }

  varia::Status chart_jets(const double* q0, const double* xi, const double* xi_dot,
                           varia::Jet2* point, varia::Jet2* velocity) noexcept override {
    varia::so3::chart_jets(q0, xi, xi_dot, point, velocity);
    return nullptr;
  }

  // log(R0^T R) at jets (so3::log is templated on the scalar).
  varia::Status local_jets(const double* q0, const varia::Jet2* q, varia::Jet2* xi) noexcept override {
    varia::so3::chart_local(q0, q, xi);
    return nullptr;
  }

  bool contains(const double* q, char* why, int why_size) noexcept override {
    for (int i = 0; i < 9; ++i)
      if (!std::isfinite(q[i])) return explain(why, why_size, "entry %d of R is not finite", i);
    const Eigen::Matrix3d R = from_row_major(q);
    const double orthogonality = varia::so3::orthogonality_error(R);
    if (orthogonality > kMembershipTolerance)
      return explain(why, why_size, "R is not orthogonal: ||I - R^T R|| = %.3g (tolerance %g)",
                     orthogonality, kMembershipTolerance);
    if (std::abs(R.determinant() - 1.0) > kMembershipTolerance)
      return explain(why, why_size, "R is a reflection, not a rotation: det R = %.17g",
                     R.determinant());
    return true;
  }

  double constraint_error(const double* q) const noexcept override {
    return varia::so3::orthogonality_error(from_row_major(q));
  }

 private:
  template <class... Args>
  static bool explain(char* why, int why_size, const char* format, Args... args) {
    if (why != nullptr && why_size > 0)
      std::snprintf(why, static_cast<std::size_t>(why_size), format, args...);
    return false;
  }
};

}  // namespace

VARIA_PLUGIN(SO3, manifold, SO3)
