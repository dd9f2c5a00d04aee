#include "errors.hpp"

#include <fmt/format.h>

#include <new>

#include "varia/abi/plugin_object.hpp"
#include "varia/core/solve/newton.hpp"

namespace varia::host {

int exit_code_of(std::exception_ptr failure, std::string& message) {
  try {
    std::rethrow_exception(failure);
  } catch (const InputError& e) {
    message = e.what();
    return kExitInput;
  } catch (const PluginLoadError& e) {
    message = e.what();
    return kExitPlugin;
  } catch (const PluginFault& e) {
    message = fmt::format("plugin fault: {}", e.what());
    return kExitPlugin;
  } catch (const NumericalFailure& e) {
    message = fmt::format("numerical failure: {}", e.what());
    return kExitNumerical;
  } catch (const std::invalid_argument& e) {  // a core constructor refusing its arguments
    message = e.what();
    return kExitInput;
  } catch (const std::bad_alloc&) {  // not a numerical failure: what was asked for is too large
    message = "out of memory: the scene or the flags ask for more memory than this machine gives";
    return kExitInput;
  } catch (const std::exception& e) {
    message = fmt::format("unexpected failure: {}", e.what());
    return kExitPlugin;
  }
}

}  // namespace varia::host
