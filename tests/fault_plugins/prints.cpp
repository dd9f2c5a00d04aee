// Fault plugin: a good oscillator that prints to stdout when it is loaded, constructed and first
// evaluated, through the C library (printf, puts), through std::cout and straight to descriptor 1.
// None of it may reach varia's results on stdout (`--out -`, `ld --json`, `plugins --json`).
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "fault_lagrangian.hpp"

namespace {
void chatter(const char* when) {
  std::printf("prints plugin: printf %s\n", when);
  std::puts("prints plugin: puts");
  std::cout << "prints plugin: std::cout " << when << std::endl;
  (void)!::write(STDOUT_FILENO, "prints plugin: write(1)\n", 24);
  std::printf("prints plugin: a line left unfinished, ");
}

const bool chattered_on_load = (chatter("on load"), true);
}  // namespace

class Prints : public varia::test::FaultLagrangian<Prints> {
 public:
  Prints(const nlohmann::json&, const varia::sdk::Context&) { chatter("in the constructor"); }
  double evaluation() {
    if (!evaluated_) chatter("in the first evaluation");
    evaluated_ = chattered_on_load;
    return 1.0;
  }

 private:
  bool evaluated_ = false;
};

VARIA_PLUGIN(Prints, lagrangian, fault_printf)
