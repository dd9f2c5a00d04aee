// Fault plugin: its evaluation calls a function that no library defines (a dependency missing on
// this machine, a plugin built against another version of a library). Loaded lazily, the call ended
// varia with the dynamic linker's "symbol lookup error" (exit 127) at the first evaluation; the
// host resolves every symbol when it loads a file, and refuses this one with the linker's reason.
#include "fault_lagrangian.hpp"

extern "C" double varia_fault_symbol_that_no_library_defines(double);

class UndefinedSymbol : public varia::test::FaultLagrangian<UndefinedSymbol> {
 public:
  UndefinedSymbol(const nlohmann::json&, const varia::sdk::Context&) {}
  double evaluation() { return varia_fault_symbol_that_no_library_defines(1.0); }
};

VARIA_PLUGIN(UndefinedSymbol, lagrangian, fault_undefined)
