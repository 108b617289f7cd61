// The preamble's system layer (parse/SystemLayer.h): after a header edit, the AST cache rebuilds the
// preamble over a kept PCH of the system headers the user's files start with. Each test compares a
// translation through the cache, after an edit, with one from a fresh cache (a cold parse): the
// layer must never change what the translator sees.
#include "parse/AstCache.h"
#include "EngineSupport.h"

using namespace crossrt::engine;

namespace {

// A class over the user's header `userHeader` (included first). Its kernel writes `value_t`, which
// the headers define: as float (translates for Vulkan) or as double (refused there by design).
struct LayeredClass {
  TempClass tc;
  explicit LayeredClass(const std::string& userHeader)
      : tc("Layered", R"(#pragma once
#include "user.h"
class Layered
{
public:
  virtual ~Layered() = default;
  virtual void Run(int n, [[crossrt::size("n")]] value_t* out);
protected:
  void kernel1D_Fill(int n, value_t* out);
};
)", R"(#include "Layered.h"
void Layered::Run(int n, value_t* out) { kernel1D_Fill(n, out); }
void Layered::kernel1D_Fill(int n, value_t* out) { for (int i = 0; i < n; i++) out[i] = value_t(i); }
)")
  {
    fs::create_directories(tc.dir / "sys");
    // A system header (found through -isystem) that reads a setting, and one that defines a macro.
    std::ofstream(tc.dir / "sys" / "real.h") << "#pragma once\n#define REAL_H_INCLUDED 1\n"
                                                "#ifdef CROSSRT_TEST_DOUBLE\ntypedef double real_t;\n#else\ntypedef float real_t;\n#endif\n";
    std::ofstream(tc.dir / "guarded.h") << "#ifndef GUARDED_H\n#define GUARDED_H\n#endif\n";
    Write(userHeader);
  }
  void Write(const std::string& userHeader) const { std::ofstream(tc.dir / "user.h") << userHeader; }
  TranslateRequest Request() const {
    TranslateRequest r = MakeRequest(tc, "Layered");
    r.compileArgs.insert(r.compileArgs.end(), {"-isystem", (tc.dir / "sys").string()});
    return r;
  }
};

// A translation through `cache` is the same as one through a fresh cache: the same success, the same
// diagnostics, the same files.
void RequireSameAsCold(const TranslateRequest& request, AstCache& cache) {
  TranslateResult warm = Translate(request, &cache);
  AstCache fresh;
  TranslateResult cold = Translate(request, &fresh);
  INFO("warm:\n" << warm.diagnostics << "\ncold:\n" << cold.diagnostics);
  REQUIRE(warm.ok == cold.ok);
  REQUIRE(warm.diagnostics == cold.diagnostics);
  REQUIRE(warm.files == cold.files);
  REQUIRE(warm.inputs == cold.inputs);
}

// Translates `header` as user.h, then adds a helper to it (at "// edits here", or at its end),
// translates again through the same cache and compares that with a cold translation; `edits` times.
// Returns the cache's statistics.
AstCacheStats EditAndCompare(const LayeredClass& layered, std::string header, int edits = 1) {
  layered.Write(header);
  AstCache cache;
  Translate(layered.Request(), &cache);
  for (int edit = 0; edit < edits; ++edit) {
    const std::string helper = "inline int EditedHelper" + std::to_string(edit) + "() { return " + std::to_string(edit) + "; }\n";
    const size_t at = header.find("// edits here");
    header.insert(at == std::string::npos ? header.size() : at, helper);
    layered.Write(header);
    RequireSameAsCold(layered.Request(), cache);
  }
  return cache.Stats();
}

}  // namespace

TEST_CASE("A header edit rebuilds the preamble over a kept layer of the system headers, as a cold parse reads it", "[engine]")
{
  LayeredClass layered("");
  const std::string header = "#pragma once\n#include <real.h>\n#include <vector>\n#include <cmath>\n#include \"LiteMath.h\"\n"
                             "typedef real_t value_t;\n";
  AstCacheStats stats = EditAndCompare(layered, header, 3);
  CHECK(stats.layers == 1);            // built on the first edit, kept for the next two
  CHECK(stats.layeredPreambles == 3);  // every edit's preamble over it
  // The translation's inputs (the depfile) still name the headers <vector> brings, read by the layer.
  AstCache cache;
  TranslateResult r = Translate(layered.Request(), &cache);
  std::ofstream(layered.tc.dir / "user.h", std::ios::app) << "// edited\n";
  r = Translate(layered.Request(), &cache);
  REQUIRE(r.ok);
  REQUIRE(cache.Stats().layeredPreambles == 1);
  CHECK(std::any_of(r.inputs.begin(), r.inputs.end(), [](const std::string& f) { return f.find("/bits/stl_vector.h") != std::string::npos; }));

  SECTION("a long-lived cache prepares the layer in the background, after the first parse or the first reparse")
  {
    layered.Write(header);
    AstCache prepared(32, AstCache::LayerPreparation::AfterParse);
    REQUIRE(Translate(layered.Request(), &prepared).ok);
    std::ofstream(layered.tc.dir / "user.h", std::ios::app) << "// edited\n";
    RequireSameAsCold(layered.Request(), prepared);
    CHECK(prepared.Stats().layers == 1);  // built once, whichever asked first
    CHECK(prepared.Stats().layeredPreambles == 1);
    // The build daemon's cache: a class translated once (a cold build) costs no layer.
    layered.Write(header);
    AstCache daemon(32, AstCache::LayerPreparation::AfterReparse);
    REQUIRE(Translate(layered.Request(), &daemon).ok);
    REQUIRE(Translate(layered.Request(), &daemon).ok);  // the same text: the AST serves as it is
    CHECK(daemon.Stats().layers == 0);
    std::ofstream(layered.tc.dir / "Layered.cpp", std::ios::app) << "// a kernel file edit: parsed again\n";
    REQUIRE(Translate(layered.Request(), &daemon).ok);
    std::ofstream(layered.tc.dir / "user.h", std::ios::app) << "// then a header edit\n";
    RequireSameAsCold(layered.Request(), daemon);
    CHECK(daemon.Stats().layers == 1);
    CHECK(daemon.Stats().layeredPreambles == 1);
  }
  SECTION("an include guard opens the prefix as #pragma once does")
  {
    stats = EditAndCompare(layered, "#ifndef USER_H\n#define USER_H\n#include <real.h>\n#include <vector>\ntypedef real_t value_t;\n"
                                    "// edits here\n#endif  // USER_H\n/* the end */\n");
    CHECK(stats.layeredPreambles == 1);
  }
  SECTION("an error typed into a header is reported from a parse over the layer alone, and the fix is seen")
  {
    layered.Write(header);
    AstCache edited;
    Translate(layered.Request(), &edited);
    std::ofstream(layered.tc.dir / "user.h", std::ios::app) << "undeclared_type broken;\n";
    RequireSameAsCold(layered.Request(), edited);
    TranslateResult r = Translate(layered.Request(), &edited);
    CHECK_FALSE(r.ok);
    CHECK(r.diagnostics.find("user.h:7:1: error: unknown type name 'undeclared_type'") != std::string::npos);
    layered.Write(header);
    RequireSameAsCold(layered.Request(), edited);
    CHECK(Translate(layered.Request(), &edited).ok);
    CHECK(edited.Stats().layers == 1);
  }
  SECTION("a system header edited on disk gets a new layer")
  {
    layered.Write("#pragma once\n#include <real.h>\n#include <vector>\n#ifndef CROSSRT_TEST_LATER\ntypedef real_t value_t;\n#endif\n");
    AstCache edited;
    Translate(layered.Request(), &edited);
    std::ofstream(layered.tc.dir / "user.h", std::ios::app) << "// edited\n";
    REQUIRE(Translate(layered.Request(), &edited).ok);  // float: translates
    std::ofstream(layered.tc.dir / "sys" / "real.h", std::ios::app) << "#define CROSSRT_TEST_LATER 1\ntypedef double value_t;\n";
    std::ofstream(layered.tc.dir / "user.h", std::ios::app) << "// edited again\n";
    RequireSameAsCold(layered.Request(), edited);
    CHECK_FALSE(Translate(layered.Request(), &edited).ok);  // double: refused on Vulkan
    CHECK(edited.Stats().layers == 2);
    CHECK(edited.Stats().layeredPreambles == 2);
  }
}

TEST_CASE("What the user's headers do before a system header keeps that header out of the layer", "[engine]")
{
  LayeredClass layered("");
  SECTION("a setting macro that the system header reads")
  {
    AstCacheStats stats = EditAndCompare(layered, "#pragma once\n#define CROSSRT_TEST_DOUBLE 1\n#include <real.h>\ntypedef real_t value_t;\n");
    CHECK(stats.layeredPreambles == 0);
  }
  SECTION("a setting written like an include guard, but closed before the file ends")
  {
    AstCacheStats stats = EditAndCompare(
        layered, "#ifndef CROSSRT_TEST_DOUBLE\n#define CROSSRT_TEST_DOUBLE\n#endif\n#include <real.h>\ntypedef real_t value_t;\n");
    CHECK(stats.layeredPreambles == 0);
  }
  SECTION("a question about a macro that a later system header defines")
  {
    // In place, REAL_H_INCLUDED is not yet defined at the #ifdef: guarded.h is not included and
    // value_t is float. With <real.h> in a layer in front, it would be double.
    AstCacheStats stats = EditAndCompare(layered, "#pragma once\n#ifdef REAL_H_INCLUDED\n#include \"guarded.h\"\n#endif\n"
                                                  "#include <real.h>\n#ifdef GUARDED_H\ntypedef double value_t;\n#else\n"
                                                  "typedef float value_t;\n#endif\n");
    CHECK(stats.layeredPreambles == 0);
  }
  SECTION("a declaration before the system header")
  {
    AstCacheStats stats = EditAndCompare(layered, "#pragma once\nstruct Before {};\n#include <real.h>\ntypedef real_t value_t;\n");
    CHECK(stats.layeredPreambles == 0);
  }
  SECTION("a pragma before the system header")
  {
    AstCacheStats stats = EditAndCompare(layered, "#pragma once\n#pragma pack(push, 1)\n#include <real.h>\n#pragma pack(pop)\ntypedef real_t value_t;\n");
    CHECK(stats.layeredPreambles == 0);
  }
  SECTION("the system headers before a setting still make a layer, the rest stays out")
  {
    AstCacheStats stats = EditAndCompare(layered, "#pragma once\n#include <vector>\n#define CROSSRT_TEST_DOUBLE 1\n#include <real.h>\ntypedef real_t value_t;\n", 2);
    CHECK(stats.layers == 1);
    CHECK(stats.layeredPreambles == 2);
  }
}
