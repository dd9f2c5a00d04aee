// Fault plugin: loading it aborts the program (a static initializer calls std::abort). The host
// must never load it for a scene that does not name its type, stripped or not (the type marker is
// read from the dynamic symbol table). Built into a directory of its own: listing it aborts.
#include <cstdlib>

#include "fault_lagrangian.hpp"

namespace {
const int aborted_on_load = (std::abort(), 0);
}

class AbortsOnLoad : public varia::test::FaultLagrangian<AbortsOnLoad> {
 public:
  AbortsOnLoad(const nlohmann::json&, const varia::sdk::Context&) { (void)aborted_on_load; }
};

VARIA_PLUGIN(AbortsOnLoad, lagrangian, fault_abort_on_load)
