// Translation in the client's own process, when no daemon can answer. The engine (Clang and
// LLVM) is loaded only then, so the common path (daemon or unchanged key) starts in a millisecond.
#pragma once
#include "TranslateTypes.h"

#include <string>

namespace crossrt::client {

// Throws std::runtime_error when the engine module cannot be loaded or fails.
engine::TranslateResult TranslateInProcess(const engine::TranslateRequest& request);

// The engine library the client loads when it translates in-process, or "" when none is found.
std::string EnginePath();

}  // namespace crossrt::client
