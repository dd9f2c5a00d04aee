// Fault plugin: an evaluation recurses without end (a stack overflow: SIGSEGV with no stack left,
// handled on the host's alternate stack). The host must name this file and end with exit code 3.
#include "fault_lagrangian.hpp"

namespace {
volatile bool deep_enough = false;  // never set: the compiler cannot end the recursion

[[gnu::noinline]] int descend(int depth) {
  volatile char frame[512];
  frame[0] = static_cast<char>(depth);
  if (deep_enough) return frame[0];
  return descend(depth + 1) + frame[0];  // not a tail call: every level keeps its frame
}
}  // namespace

class OverflowsStack : public varia::test::FaultAfter<OverflowsStack> {
 public:
  OverflowsStack(const nlohmann::json& parameters, const varia::sdk::Context&) : FaultAfter(parameters) {}
  static void fault() { (void)descend(0); }
};

VARIA_PLUGIN(OverflowsStack, lagrangian, fault_stack_overflow)
