// The Duffing oscillator x'' = -alpha x - beta x^3 (by default alpha = beta = 1) as a varia
// Lagrangian plugin: L = v^2/2 - alpha x^2/2 - beta x^4/4, written once for any scalar; varia's
// SDK differentiates it exactly (forward-mode AD).
#include <varia/sdk/autodiff_lagrangian.hpp>

class Duffing : public varia::sdk::AutodiffLagrangian<Duffing> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "type": "object",
    "properties": {
      "alpha": {"type": "number", "default": 1},
      "beta": {"type": "number", "default": 1}
    },
    "additionalProperties": false
  })";
  static constexpr const char* properties =
      R"({"energy": "v^2/2 + alpha x^2/2 + beta x^4/4", "symmetry": "none"})";

  Duffing(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(1, 1),
        alpha_(parameters.value("alpha", 1.0)),
        beta_(parameters.value("beta", 1.0)) {
    if (context.manifold != "Rn" || context.dim != 1)
      throw std::invalid_argument("duffing needs manifold Rn with dim 1");
  }

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    const T x2 = q(0) * q(0);
    return 0.5 * v(0) * v(0) - 0.5 * alpha_ * x2 - 0.25 * beta_ * x2 * x2;
  }

 private:
  double alpha_, beta_;
};

VARIA_PLUGIN(Duffing, lagrangian, duffing)
