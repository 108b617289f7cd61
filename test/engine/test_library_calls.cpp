// The library-call rewriting of control functions (LibraryCalls.cpp): std::sort, std::exclusive_scan,
// std::fill and memcpy on member vectors become the runtime's GPU primitives in the Vulkan class's
// ...Cmd, stay as written in the CPU class, and what the GPU cannot run gets a diagnostic.
#include "EngineSupport.h"

#include <algorithm>

using namespace crossrt::engine;

namespace {

const char* kHeader = R"(#pragma once
#include "LiteMath.h"
#include <vector>
#include <cstdint>
using namespace LiteMath;
class Library
{
public:
  virtual ~Library() = default;
  virtual void Prepare(int n);
  virtual void Compact(int n);
protected:
  void kernel1D_Keys(int n);
  void kernel1D_Flags(int n);
  std::vector<uint32_t> m_keys, m_flags, m_offsets, m_copy;
};
)";

std::string Source(const std::string& prepare)
{
  return std::string(R"(#include "Library.h"
#include <algorithm>
#include <cstring>
#include <functional>
#include <numeric>
void Library::Prepare(int n)
{
)") + prepare + R"(}
void Library::Compact(int n)
{
  kernel1D_Flags(n);
  std::exclusive_scan(m_flags.begin(), m_flags.begin() + n, m_offsets.begin(), 0u);
}
void Library::kernel1D_Keys(int n)
{
  for (int i = 0; i < n; ++i) m_keys[i] = uint32_t(n - i);
}
void Library::kernel1D_Flags(int n)
{
  for (int i = 0; i < n; ++i) m_flags[i] = m_keys[i] & 1u;
}
)";
}
}  // namespace

TEST_CASE("Library calls: sort, scan, fill and memcpy on member vectors become GPU primitives", "[engine][library]")
{
  TempClass tc("Library", kHeader, Source("  std::fill(m_flags.begin(), m_flags.end(), 0u);\n  kernel1D_Keys(n);\n"
                                          "  std::sort(m_keys.begin(), m_keys.begin() + n);\n"
                                          "  memcpy(m_copy.data(), m_keys.data(), n * sizeof(uint32_t));\n"));
  const AnalyzeResult r = Analyze(MakeRequest(tc, "Library"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::string prepare = Squeezed(ControlNamed(r.model, "Prepare").vulkanCmdBody);
  INFO(prepare);
  // Each call, in the order written, on the members' device buffers; counts as the user wrote them.
  const size_t fill = prepare.find(Squeezed("crossrt::FillCmd(crt_cmd, crt_vdata.m_flags.View(), sizeof(unsigned int) * VkDeviceSize(m_flags.size())"));
  const size_t keys = prepare.find(Squeezed("kernel1D_KeysCmd(crt_cmd, n)"));
  const size_t sort = prepare.find(Squeezed("crt_sorter.RecordCmd(crt_cmd, crt_vdata.m_keys.View(), uint32_t(n),"));
  const size_t copy = prepare.find(Squeezed("crossrt::CopyCmd(crt_cmd, crt_vdata.m_keys.View(), crt_vdata.m_copy.View(), VkDeviceSize(n * sizeof(uint32_t)))"));
  REQUIRE(fill != std::string::npos);
  REQUIRE(keys != std::string::npos);
  REQUIRE(sort != std::string::npos);
  REQUIRE(copy != std::string::npos);
  CHECK((fill < keys && keys < sort && sort < copy));
  CHECK(prepare.find("std::sort") == std::string::npos);
  // The scan writes its output vector, which the host then reads back.
  const Control& compact = ControlNamed(r.model, "Compact");
  CHECK(Squeezed(compact.vulkanCmdBody).find(Squeezed("crt_scanner.RecordCmd(crt_cmd, crt_vdata.m_flags.View(), crt_vdata.m_offsets.View(), uint32_t(n), false")) !=
        std::string::npos);
  CHECK(std::find(compact.vectorsWritten.begin(), compact.vectorsWritten.end(), "m_offsets") != compact.vectorsWritten.end());
  // The generated class holds a sorter and a scanner because control functions use them.
  CHECK(r.model.usesSorter);
  CHECK(r.model.usesScanner);
}

TEST_CASE("Library calls: the CPU class sorts on all cores and runs the rest as written", "[engine][library]")
{
  TempClass tc("Library", kHeader, Source("  std::fill(m_flags.begin(), m_flags.end(), 0u);\n  kernel1D_Keys(n);\n"
                                          "  std::sort(m_keys.begin(), m_keys.begin() + n);\n"));
  const AnalyzeResult r = Analyze(MakeRequest(tc, "Library", Backend::Cpu));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  const std::string prepare = Squeezed(ControlNamed(r.model, "Prepare").cpuBody);
  INFO(prepare);
  CHECK(prepare.find(Squeezed("std::fill(m_flags.begin(), m_flags.end(), 0u);")) != std::string::npos);
  CHECK(prepare.find(Squeezed("crossrt::RadixSort(m_keys.begin(), m_keys.begin() + n, crossrt::SortKey{1, 0, crossrt::ElementType::Uint, false})")) !=
        std::string::npos);
  CHECK(prepare.find("std::sort") == std::string::npos);
  CHECK(prepare.find("crt_sorter") == std::string::npos);
}

TEST_CASE("Library calls: without sorts or scans the class has no sorter or scanner", "[engine][library]")
{
  TempClass tc("Library", kHeader, Source("  kernel1D_Keys(n);\n"));
  const TranslateResult r = Translate(MakeRequest(tc, "Library"));
  INFO(r.diagnostics);
  REQUIRE(r.ok);
  // Compact still scans: the scanner stays, the sorter goes.
  const std::string header = r.files.at("Library_Vulkan.h");
  CHECK(header.find("crossrt::Scanner crt_scanner;") != std::string::npos);
  CHECK(header.find("crt_sorter") == std::string::npos);
}

TEST_CASE("Library calls: a comparator the GPU sort has no key for is a diagnostic", "[engine][library]")
{
  TempClass tc("Library", kHeader, Source("  kernel1D_Keys(n);\n  std::sort(m_keys.begin(), m_keys.end(), [](uint32_t a, uint32_t b) { return a % 7 < b % 7; });\n"));
  const AnalyzeResult r = Analyze(MakeRequest(tc, "Library"));
  CHECK_FALSE(r.ok);
  CHECK(r.diagnostics.find("Library.cpp:9:3: error:") != std::string::npos);
  CHECK(r.diagnostics.find("hint:") != std::string::npos);
}
