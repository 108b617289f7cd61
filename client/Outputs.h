// Writing generated files: atomically, and only files whose bytes changed, so that no
// timestamp moves without reason and nothing recompiles needlessly.
#pragma once
#include "TranslateTypes.h"

#include <string>
#include <vector>

namespace crossrt::client {

// Returns the names of the files it rewrote. Throws std::runtime_error with a clear message.
std::vector<std::string> WriteOutputs(const engine::TranslateRequest& request, const engine::TranslateResult& result);

}  // namespace crossrt::client
