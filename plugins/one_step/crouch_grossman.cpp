// Explicit Crouch-Grossman methods (Crouch & Grossman 1993; Hairer, Lubich & Wanner, sec. IV.8):
// Lie group methods for y' = y . xi(y) (VectorField::algebra, VectorField::move), the paper's LGM
// of Figure 1 (sec. 2). With the left-trivialized field the stages and the step are products of
// exponentials on the right,
//   Y_i = y0 . exp(h a_i1 K_1) ... exp(h a_{i,i-1} K_{i-1}),   K_i = xi(Y_i),
//   y1  = y0 . exp(h b_1 K_1) ... exp(h b_s K_s),
// which stay on the group and commute with left multiplication ("left"). Order 2 is the explicit
// midpoint rule on the group, R_{k+1} = R_k exp(h Omega_{k+1/2}); order 3 Crouch and Grossman's
// 3-stage method. Where the group is R^N (translations) the method is the Runge-Kutta method of
// the same tableau. Explicit; not self-adjoint, not symplectic.
#include <Eigen/Core>
#include <cmath>
#include <type_traits>
#include <vector>

#include "varia/abi/one_step.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

using varia::Jet2;
using varia::Status;
using varia::VectorField;

// a strictly lower triangular, b the weights.
struct Tableau {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
};

Tableau tableau(int order) {
  if (order == 2) {
    Tableau t{Eigen::MatrixXd::Zero(2, 2), Eigen::Vector2d(0.0, 1.0)};
    t.a(1, 0) = 0.5;
    return t;
  }
  Tableau t{Eigen::MatrixXd::Zero(3, 3), Eigen::Vector3d(13.0 / 51, -2.0 / 3, 24.0 / 17)};
  t.a(1, 0) = 3.0 / 4;
  t.a(2, 0) = 119.0 / 216;
  t.a(2, 1) = 17.0 / 108;
  return t;
}

int order_parameter(const nlohmann::json& parameters) {
  for (const auto& item : parameters.items())
    if (item.key() != "order")
      throw std::invalid_argument("crouch-grossman: unknown parameter '" + item.key() +
                                  "' (the only parameter is 'order')");
  const auto value = parameters.value("order", nlohmann::json(2));
  if (value != 2 && value != 3)
    throw std::invalid_argument("crouch-grossman: 'order' must be 2 or 3, got " + value.dump());
  return value.get<int>();
}

class CrouchGrossman final : public varia::OneStepMethod {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "order": {"enum": [2, 3], "default": 2,
                "description": "2: explicit midpoint on the group; 3: Crouch-Grossman's 3 stages"}
    },
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"({
    "order": "order",
    "self_adjoint": false,
    "symplectic": false,
    "equivariance": "left",
    "implicit": false
  })";

  CrouchGrossman(const nlohmann::json& parameters, const varia::sdk::Context&)
      : order_(order_parameter(parameters)), t_(tableau(order_)) {}

  int order() const noexcept override { return order_; }
  bool self_adjoint() const noexcept override { return false; }
  const char* equivariance() const noexcept override { return "left"; }
  void set_solver(double, int) noexcept override {}  // explicit: nothing to solve
  Status step(VectorField& field, double h, const double* y0, double* y1,
              varia::StageSolve* report) noexcept override {
    return varia::sdk::guarded(error_, [&] { advance(field, h, y0, y1, *report); });
  }
  Status step(VectorField& field, double h, const Jet2* y0, Jet2* y1,
              varia::StageSolve* report) noexcept override {
    return varia::sdk::guarded(error_, [&] { advance(field, h, y0, y1, *report); });
  }

 private:
  template <class T>
  struct Workspace {
    std::vector<T> K, Y, moved, xi;  // stages K_i (s blocks of the algebra), a point, a step
  };

  static void check(Status status) {
    if (status != nullptr) throw std::runtime_error(status);
  }

  // y <- y . exp(h c K) for each (c, K) with c != 0, in order.
  template <class T>
  static void compose(VectorField& field, double h, const Eigen::VectorXd& c, int count,
                      Workspace<T>& w, T* y) {
    const int N = field.size(), n = field.algebra_size();
    for (int j = 0; j < count; ++j) {
      if (c(j) == 0.0) continue;
      for (int r = 0; r < n; ++r) w.xi[r] = (h * c(j)) * w.K[j * n + r];
      check(field.move(y, w.xi.data(), w.moved.data()));
      std::copy(w.moved.begin(), w.moved.begin() + N, y);
    }
  }

  template <class T>
  void advance(VectorField& field, double h, const T* y0, T* y1, varia::StageSolve& report) {
    const int N = field.size(), n = field.algebra_size(), s = static_cast<int>(t_.b.size());
    Workspace<T>* w;
    if constexpr (std::is_same_v<T, double>) w = &doubles_;
    else w = &jets_;
    w->K.resize(s * n);
    w->Y.resize(N);
    w->moved.resize(N);
    w->xi.resize(n);
    report = varia::StageSolve{};
    for (int i = 0; i < s; ++i) {
      std::copy(y0, y0 + N, w->Y.begin());
      compose(field, h, Eigen::VectorXd(t_.a.row(i).transpose()), i, *w, w->Y.data());
      check(field.algebra(w->Y.data(), &w->K[i * n]));
    }
    std::copy(y0, y0 + N, y1);
    compose(field, h, t_.b, s, *w, y1);
  }

  int order_;
  Tableau t_;
  std::string error_;
  // Workspace, sized on the first step.
  Workspace<double> doubles_;
  Workspace<Jet2> jets_;
};

}  // namespace

VARIA_PLUGIN(CrouchGrossman, one_step, crouch_grossman)
