// Runs every conformance case on each backend and prints which constructs pass:
//   crossrt_conformance [--csv FILE]
// Exit status 0 only when every case agrees with the class as written on every backend the build
// has (_CPU, _Vulkan, and _ISPC where an ISPC compiler was found), and every refusal by design is
// the diagnostic the case expects.
#include "Conformance.h"
#include "CommandLine.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

namespace conformance {

std::vector<Case>& Registry() {
  static std::vector<Case> cases;
  return cases;
}

std::shared_ptr<crossrt::VulkanContext> Context() {
  static std::shared_ptr<crossrt::VulkanContext> ctx = [] {
    crossrt::ContextOptions options;
    options.validation = true;
    const char* device = std::getenv("CROSSRT_DEVICE");
    options.device = device ? device : "";
    try {
      return crossrt::VulkanContext::Create(options);
    } catch (const crossrt::NoDeviceError&) {
      return std::shared_ptr<crossrt::VulkanContext>();
    }
  }();
  return ctx;
}

}  // namespace conformance

namespace {

using conformance::Case;
using conformance::Run;

struct Verdict {
  bool pass = false;
  std::string text;
};

// A translated run against the original's outputs.
Verdict Compare(const Run& original, const Run& translated, double tolerance) {
  if (!translated.ran) return {false, "threw: " + translated.error};
  if (translated.outputs.size() != original.outputs.size())
    return {false, "gave " + std::to_string(translated.outputs.size()) + " values, not " + std::to_string(original.outputs.size())};
  double worst = 0.0;
  size_t at = 0;
  for (size_t i = 0; i < original.outputs.size(); ++i) {
    const double a = original.outputs[i], b = translated.outputs[i];
    const double d = a == b || (std::isnan(a) && std::isnan(b)) ? 0.0 : std::fabs(a - b) / std::max(1.0, std::fabs(a));  // (equal infinities: 0)
    if (std::isnan(d)) {  // a NaN on one side only: the verdict, kept (a later 0 must not replace it)
      worst = d;
      at = i;
      break;
    }
    if (d > worst) {
      worst = d;
      at = i;
    }
  }
  char buf[96];
  if (worst <= tolerance) {
    std::snprintf(buf, sizeof buf, "ok (%.1e)", worst);
    return {true, buf};
  }
  std::snprintf(buf, sizeof buf, "differs: %.3g at [%zu]", worst, at);
  return {false, buf};
}

// Translates the class for Vulkan with the real crossrt command and checks that it refuses it with
// the expected diagnostic.
Verdict CheckRefusal(const Case& c) {
  namespace fs = std::filesystem;
  const std::string source = std::string(CONFORMANCE_CASES_DIR) + "/" + c.files.substr(0, c.files.find('.')) + ".cpp";
  const fs::path out = fs::temp_directory_path() / ("crossrt-conformance-" + std::to_string(::getpid()));
  const std::string command = std::string(CROSSRT_CLIENT) + " translate --no-daemon --backend vulkan --class " +
                              c.className + " --out " + out.string() + " --candidate " + source +
                              " --templates " CROSSRT_TEMPLATE_DIR " -- -I" CONFORMANCE_CASES_DIR " " CONFORMANCE_INCLUDES " 2>&1";
  std::string output;
  if (FILE* p = ::popen(command.c_str(), "r")) {
    char buf[4096];
    for (size_t got; (got = std::fread(buf, 1, sizeof buf, p)) > 0;) output.append(buf, got);
    const int status = ::pclose(p);
    std::error_code ec;
    const bool wroteNothing = !fs::exists(out, ec) || fs::is_empty(out, ec);
    fs::remove_all(out, ec);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 1 && wroteNothing && output.find(c.vulkanRefusal) != std::string::npos)
      return {true, "refused: " + c.vulkanRefusal};
  }
  return {false, "expected refusal '" + c.vulkanRefusal + "', got: " + output.substr(0, 300)};
}

std::string Cell(const std::string& s, size_t width) { return s.size() > width ? s.substr(0, width - 3) + "..." : s + std::string(width - s.size(), ' '); }

}  // namespace

int main(int argc, char** argv) {
  std::string csvPath;
  crossrt::CommandLine app("crossrt_conformance",
                           "Runs the conformance classes (test/conformance/cases) as written, as _CPU, as _Vulkan and (where the\n"
                           "build found an ISPC compiler) as _ISPC, and prints which constructs translate, run and agree.\n"
                           "CROSSRT_DEVICE picks the Vulkan device.");
  app.add_option("--csv", csvPath, "the table as CSV too");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  auto& cases = conformance::Registry();
  std::sort(cases.begin(), cases.end(), [](const Case& a, const Case& b) { return a.files < b.files; });
  auto ctx = conformance::Context();
#ifdef CONFORMANCE_ISPC
  const bool ispcBuilt = true;
#else
  const bool ispcBuilt = false;
#endif
  std::printf("CrossRT conformance: %zu classes on the CPU, on Vulkan (%s, validation on) and in ISPC%s\n\n", cases.size(),
              ctx ? ctx->DeviceName().c_str() : "no Vulkan driver: Vulkan column skipped",
              ispcBuilt ? "" : " (no ISPC compiler in this build: ISPC column skipped)");
  const size_t w0 = 62, w1 = 26, w2 = 22;
  std::printf("%s | %s | %s | %s | %s\n", Cell("construct", w0).c_str(), Cell("class (cases/)", w1).c_str(), Cell("_CPU", w2).c_str(),
              Cell("_Vulkan", w2).c_str(), "_ISPC");
  std::printf("%s-+-%s-+-%s-+-%s-+-%s\n", std::string(w0, '-').c_str(), std::string(w1, '-').c_str(), std::string(w2, '-').c_str(),
              std::string(w2, '-').c_str(), std::string(w2, '-').c_str());
  std::ofstream csv;
  if (!csvPath.empty()) {
    csv.open(csvPath);
    csv << "construct,files,cpu,vulkan,ispc\n";
  }
  int failures = 0, passes = 0;
  for (const Case& c : cases) {
    const Run original = c.original();
    Verdict cpu, vulkan, ispc;
    if (!original.ran) {
      cpu = vulkan = ispc = {false, "original threw: " + original.error};
    } else if (std::all_of(original.outputs.begin(), original.outputs.end(), [](double v) { return v == 0.0; })) {
      cpu = vulkan = ispc = {false, "the original computed nothing"};  // a check that cannot fail
    } else {
      cpu = Compare(original, c.cpu(), c.tolerance);
      if (!c.vulkanRefusal.empty()) vulkan = CheckRefusal(c);
      else if (!ctx) vulkan = {true, "skipped: no Vulkan driver"};
      else {
        vulkan = Compare(original, c.vulkan(), c.tolerance);
        for (auto& m : ctx->ValidationMessages()) vulkan = {false, "validation: " + m};
        ctx->ClearValidationMessages();
      }
      if (!ispcBuilt) ispc = {true, "skipped: no ISPC compiler"};
      else if (c.ispc) ispc = Compare(original, c.ispc(), c.tolerance);
      else ispc = {false, "no _ISPC class: the build translated it for ISPC but the case does not run it"};
    }
    const bool pass = cpu.pass && vulkan.pass && ispc.pass;
    (pass ? passes : failures)++;
    std::printf("%s | %s | %s | %s | %s%s\n", Cell(c.construct, w0).c_str(), Cell(c.files, w1).c_str(), Cell(cpu.text, w2).c_str(),
                Cell(vulkan.text, w2).c_str(), ispc.text.c_str(), pass ? "" : "   <-- FAIL");
    if (csv) csv << '"' << c.construct << "\",\"" << c.files << "\",\"" << cpu.text << "\",\"" << vulkan.text << "\",\"" << ispc.text << "\"\n";
  }
  if (cases.size() != CONFORMANCE_EXPECTED_CASES) {
    std::printf("\n%zu cases ran, but the build translated %d classes: a case is missing its check\n", cases.size(), CONFORMANCE_EXPECTED_CASES);
    ++failures;
  }
  std::printf("\n%d of %zu constructs translate, run and agree on every backend%s\n", passes, cases.size(),
              failures ? "" : " (OK)");
  return failures == 0 ? 0 : 1;
}
