// The engine as a loadable module, for the client's in-process fallback. The client links no
// Clang (it starts in a millisecond); only when no daemon can answer does it dlopen this module
// and translate here, in its own process.
#include "Protocol.h"
#include "Translator.h"

#include <cstdlib>
#include <cstring>

extern "C" {

// Takes a translate request as JSON (the "request" object of the protocol), returns the
// protocol's response JSON. Free the result with crossrt_engine_free().
__attribute__((visibility("default"))) char* crossrt_engine_translate(const char* requestJson) {
  nlohmann::json response;
  try {
    auto request = crossrt::protocol::RequestFromJson(nlohmann::json::parse(requestJson));
    response = crossrt::protocol::ResultToJson(crossrt::engine::Translate(request));
  } catch (const std::exception& e) {
    response = {{"ok", false}, {"error", std::string("internal error: ") + e.what()}};
  }
  std::string text = response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  char* out = static_cast<char*>(std::malloc(text.size() + 1));
  std::memcpy(out, text.c_str(), text.size() + 1);
  return out;
}

__attribute__((visibility("default"))) void crossrt_engine_free(char* text) { std::free(text); }

__attribute__((visibility("default"))) const char* crossrt_engine_version() { return crossrt::engine::kTranslatorVersion; }
}
