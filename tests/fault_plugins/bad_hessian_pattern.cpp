// Fault plugin: the oscillator declaring a sparse Hessian whose last entry lies far outside its
// 2 x 2 Hessian over (q, v). The host must refuse it when the scene is assembled (exit 3, naming
// the plugin file and the entry), before anything writes through the pattern.
#include "fault_lagrangian.hpp"

class BadHessianPattern : public varia::test::FaultLagrangian<BadHessianPattern> {
 public:
  BadHessianPattern(const nlohmann::json&, const varia::sdk::Context&) {}

  // The entries in the order evaluate() writes its Hessian values: (q, q), (v, q), (q, v), and a
  // (v, v) that names row and column 1 << 28.
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    static constexpr int kRows[] = {0, 1, 0, 1 << 28}, kCols[] = {0, 0, 1, 1 << 28};
    *rows = kRows;
    *cols = kCols;
    return 4;
  }
};

VARIA_PLUGIN(BadHessianPattern, lagrangian, fault_bad_pattern)
