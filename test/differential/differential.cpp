// The differential tester (issue 52): each random class generate.py wrote is run as written, as
// <Class>_CPU, as <Class>_Vulkan (lavapipe or the device CROSSRT_DEVICE names, validation layers
// on) and, where an ISPC compiler was found, as <Class>_ISPC. Run is called twice (the second sees
// what the first left on the device), and everything the class holds after each call is compared
// with the original's: integers exactly, floats to 1e-3 of max(1, |value|) (the GPU's division may round
// differently), the appended vector as a set (kernels append in any order).
//
//   crossrt_differential [--verbose]    prints a line per mismatch and "N passed, M failed"
#include "CommandLine.h"

#include <crossrt/VulkanRuntime.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#define DIFFERENTIAL_INCLUDES
#include "includes.inc"
#undef DIFFERENTIAL_INCLUDES

namespace {

struct Value {
  std::string name;
  double value;
  bool exact;
};

template <class T>
std::vector<Value> Outputs(T& c) {
  std::vector<Value> out;
  for (size_t i = 0; i < c.m_a.size(); ++i) out.push_back({"m_a[" + std::to_string(i) + "]", c.m_a[i], false});
  for (size_t i = 0; i < c.m_b.size(); ++i) out.push_back({"m_b[" + std::to_string(i) + "]", c.m_b[i], false});
  for (size_t i = 0; i < c.m_i.size(); ++i) out.push_back({"m_i[" + std::to_string(i) + "]", double(c.m_i[i]), true});
  for (size_t i = 0; i < c.m_hist.size(); ++i) out.push_back({"m_hist[" + std::to_string(i) + "]", double(c.m_hist[i]), true});
  std::vector<int> found = c.m_found;
  std::sort(found.begin(), found.end());
  out.push_back({"m_found.size()", double(found.size()), true});
  for (size_t i = 0; i < found.size(); ++i) out.push_back({"sorted m_found[" + std::to_string(i) + "]", double(found[i]), true});
  for (int i = 0; i < 4; ++i) out.push_back({"m_bins[" + std::to_string(i) + "]", c.m_bins[i], false});
  out.push_back({"m_sum", c.m_sum, false});
  out.push_back({"m_max", c.m_max, false});
  out.push_back({"m_scale", c.m_scale, false});
  out.push_back({"m_total", c.m_total, false});
  out.push_back({"m_count", double(c.m_count), true});
  out.push_back({"m_k", double(c.m_k), true});
  out.push_back({"m_rounds", double(c.m_rounds), true});
  out.push_back({"m_mode", double(c.m_mode), true});
  return out;
}

std::shared_ptr<crossrt::VulkanContext> Context() {
  static std::shared_ptr<crossrt::VulkanContext> ctx = [] {
    crossrt::ContextOptions options;
    options.validation = true;
    const char* device = std::getenv("CROSSRT_DEVICE");
    options.device = device ? device : "";
    return crossrt::VulkanContext::Create(options);
  }();
  return ctx;
}

struct Case {
  std::string name;
  std::function<std::vector<Value>()> original;
  std::vector<std::pair<std::string, std::function<std::vector<Value>()>>> translated;
};

template <class T>
std::function<std::vector<Value>()> Runner(std::function<std::shared_ptr<T>()> make, int n, int p, float q) {
  return [=] {
    std::shared_ptr<T> c = make();
    c->CommitDeviceData();
    c->Run(n, p, q);
    std::vector<Value> out = Outputs(*c);
    for (Value& v : out) v.name = "after the first Run: " + v.name;
    c->Run(n, p, q);
    for (const Value& v : Outputs(*c)) out.push_back({"after the second Run: " + v.name, v.value, v.exact});
    return out;
  };
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
#define DIFFERENTIAL_CASE(Class, seed, n, p, q)                                                                         \
  {                                                                                                                   \
    Case c;                                                                                                           \
    c.name = #Class;                                                                                                  \
    c.original = Runner<Class>([] { return std::make_shared<Class>(); }, n, p, q);                                  \
    c.translated.push_back({"_CPU", Runner<Class>([] { return Create##Class##_CPU(); }, n, p, q)});                   \
    c.translated.push_back({"_Vulkan", Runner<Class>([] { return Create##Class##_Vulkan(Context()); }, n, p, q)});    \
    DIFFERENTIAL_ISPC(Class, n, p, q)                                                                                 \
    cases.push_back(std::move(c));                                                                                    \
  }
#ifdef DIFFERENTIAL_WITH_ISPC
#define DIFFERENTIAL_ISPC(Class, n, p, q) c.translated.push_back({"_ISPC", Runner<Class>([] { return Create##Class##_ISPC(); }, n, p, q)});
#else
#define DIFFERENTIAL_ISPC(Class, n, p, q)
#endif
#include "cases.inc"
  return cases;
}

}  // namespace

int main(int argc, char** argv) {
  bool verbose = false;
  crossrt::CommandLine app("crossrt_differential", "Runs each random class of this build as written, as _CPU, _Vulkan and _ISPC, and compares.");
  app.add_flag("--verbose", verbose, "print every case, not only mismatches");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  int passed = 0, failed = 0;
  for (const Case& c : Cases()) {
    const std::vector<Value> expected = c.original();
    for (const auto& [backend, run] : c.translated) {
      std::string problem;
      try {
        const std::vector<Value> got = run();
        if (got.size() != expected.size())
          problem = std::to_string(got.size()) + " values, not " + std::to_string(expected.size()) + " (m_found's size differs)";
        for (size_t i = 0; problem.empty() && i < got.size(); ++i) {
          const double want = expected[i].value, have = got[i].value;
          const bool same = expected[i].exact ? want == have : std::abs(want - have) <= 1e-3 * std::max(1.0, std::abs(want));
          if (!same) problem = expected[i].name + " is " + std::to_string(have) + ", the original's " + std::to_string(want);
        }
      } catch (const std::exception& e) {
        problem = std::string("threw: ") + e.what();
      }
      if (problem.empty() && backend == "_Vulkan" && Context()->ValidationMessageCount() > 0) {
        problem = "validation: " + Context()->ValidationMessages().front();
        Context()->ClearValidationMessages();
      }
      if (problem.empty()) {
        ++passed;
        if (verbose) std::printf("%s%s: agrees\n", c.name.c_str(), backend.c_str());
      } else {
        ++failed;
        std::printf("MISMATCH %s%s: %s\n", c.name.c_str(), backend.c_str(), problem.c_str());
      }
    }
  }
  std::printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
