// The driver: one translation, pass by pass. Analyze() parses the sources and runs the analysis
// passes over each AST; Translate() generates, lays out and compiles. Each step below is one line
// naming a pass; the passes live in files of their own (README.md lists them).
#include "Translator.h"

#include "analyse/Analysis.h"
#include "parse/Arguments.h"
#include "parse/AstCache.h"
#include "generate/Canonical.h"
#include "generate/CodeGen.h"
#include "generate/CodeGenSupport.h"
#include "compile/NoContraction.h"
#include "compile/Spirv.h"

#include <clang/AST/ASTContext.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Frontend/TextDiagnosticPrinter.h>
#include <clang/Lex/Preprocessor.h>
#include <llvm/ADT/SmallString.h>
#include <llvm/Support/FileSystem.h>
#include <llvm/Support/Path.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <set>
#include <stdexcept>

namespace crossrt::engine {

void LinkSizeAttribute();

namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The request's sources as absolute paths, sorted (one handle per file, always locked in the same
// order: no self- or cross-request deadlock), or a diagnostic.
std::vector<std::string> ResolveSources(const TranslateRequest& request, std::string& diagnostics) {
  std::vector<std::string> sources;
  for (auto& s : request.sources) {
    llvm::SmallString<256> abs(s);
    llvm::sys::fs::make_absolute(abs);
    llvm::sys::path::remove_dots(abs, true);
    if (!llvm::sys::fs::exists(abs)) {
      diagnostics = "error: source file '" + s + "' does not exist\n";
      return {};
    }
    sources.push_back(std::string(abs));
  }
  std::sort(sources.begin(), sources.end());
  sources.erase(std::unique(sources.begin(), sources.end()), sources.end());
  if (sources.empty()) diagnostics = "error: no source files given for class '" + request.className + "'\n";
  return sources;
}

// Every file the ASTs read is an input of the translation (for depfiles and cache keys), by its
// real path: Clang reaches the GCC headers as /../lib/gcc/<triple>/12/../../../../include, which a
// build tool shortens without following /lib -> /usr/lib to a file that does not exist, and then
// rebuilds on every run.
std::set<std::string> InputsRead(const std::vector<AstCache::Handle>& handles) {
  std::set<std::string> inputs;
  for (auto& handle : handles)
    for (const std::string& name : handle.ast()->Includes().files) {
      std::error_code ec;
      const std::filesystem::path real = std::filesystem::weakly_canonical(name, ec);
      inputs.insert(ec ? name : real.string());
    }
  return inputs;
}

// The passes ask the AST for parents (ASTContext::getParents), of the user's code only. Clang builds
// its parent map on the first question by walking its traversal scope, the whole translation unit
// unless told otherwise: with the C++ library, about 130 ms of each reparse of examples/bloom. The
// scope is the declarations outside system headers.
void ParentsOfUserCodeOnly(clang::ASTContext& ctx) {
  std::vector<clang::Decl*> scope;
  const clang::SourceManager& sm = ctx.getSourceManager();
  for (clang::Decl* d : ctx.getTranslationUnitDecl()->decls())
    if (!sm.isInSystemHeader(sm.getExpansionLoc(d->getLocation()))) scope.push_back(d);
  if (ctx.getTraversalScope() != scope) ctx.setTraversalScope(scope);  // (setting it drops the map: an AST used again keeps it)
}

// "ISceneObject=BVHScene" -> {ISceneObject: BVHScene}, or a diagnostic.
bool ParseCompositions(const TranslateRequest& request, std::map<std::string, std::string>& out, std::string& diagnostics) {
  for (auto& c : request.compositions) {
    auto eq = c.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == c.size()) {
      diagnostics = "error: composition '" + c + "' is not of the form Interface=Implementation (e.g. ISceneObject=BVHScene)\n";
      return false;
    }
    out[c.substr(0, eq)] = c.substr(eq + 1);
  }
  return true;
}

// What only the whole picture shows: a composed implementation no source defined, a class that is
// not there or has no kernels. Empty when all is well.
std::string WholeClassProblems(const TranslateRequest& request, const ClassModel& model, const std::string& firstSource) {
  if (model.className.empty())
    return "error: class '" + request.className + "' is not defined in " + firstSource +
           " or the headers it includes\nnote: hint: check the name given to crossrt_add_class; name a class in a namespace with it "
           "(demo::Render)\n";
  for (auto& comp : model.compositions)
    if (request.backend == Backend::Vulkan && comp.implHeader.empty())
      return "error: " + request.className + "'s kernels call " + comp.interfaceName + " through '" + comp.holder + "', composed as " +
             comp.implName + ", but no source file defines class " + comp.implName +
             " with the bodies of the methods they call\nnote: hint: list the implementation's source file (e.g. BVHScene.cpp) in "
             "crossrt_add_class(... SOURCES ...)\n";
  if (model.kernels.empty() && model.blockKernels.empty())
    return model.headerFile + ": error: class '" + request.className +
           "' has no kernels\nnote: hint: kernels are member functions named kernel1D_*, kernel2D_*, kernel3D_* (holding loops) or "
           "kernel_* (taking tid)\n";
  return "";
}

// The shaders compiled to SPIR-V (unchanged ones from the cache) and embedded in one C++ source.
// Unless `contract`, no multiply and add may be fused (NoContraction.h).
std::string CompileShaders(const std::string& className, const std::vector<ShaderSource>& shaders, SpirvCache* spirvCache, bool contract) {
  std::vector<std::pair<std::string, std::vector<uint32_t>>> spirv;
  for (auto& shader : shaders) {
    std::vector<uint32_t> words;
    const std::string key = (contract ? "// -ffp-contract=fast\n" : "") + shader.glsl;
    if (!spirvCache || !spirvCache->Find(key, words)) {
      words = CompileGlsl(shader.name, shader.glsl, shader.stage);
      if (!contract) ForbidContraction(words);
      if (spirvCache) spirvCache->Add(key, words);
    }
    spirv.push_back({shader.name, words});
  }
  return EmbedSpirv(className, spirv);
}

}  // namespace

AnalyzeResult Analyze(const TranslateRequest& request, AstCache* sharedCache) {
  LinkSizeAttribute();
  AnalyzeResult result;
  std::map<std::string, std::string> compositions;
  const std::vector<std::string> sources = ResolveSources(request, result.diagnostics);
  if (sources.empty() || !ParseCompositions(request, compositions, result.diagnostics)) return result;
  const std::vector<std::string> args = ParseArguments(request);
  for (auto& s : sources)
    if (std::string problem = GeneratedIncludeProblem(s, args); !problem.empty()) {
      result.diagnostics = problem;
      return result;
    }

  // Parse: each source into an AST, reparsed from the daemon's cache when it has one.
  auto t0 = std::chrono::steady_clock::now();
  AstCache localCache(sources.size());
  AstCache& cache = sharedCache ? *sharedCache : localCache;
  std::vector<AstCache::Handle> handles;
  std::string diagText;
  bool parseErrors = false;
  for (auto& s : sources) {
    handles.push_back(cache.Get(s, args, request.unsavedFiles));
    diagText += handles.back().diagnostics();
    parseErrors |= handles.back().failed();
  }
  if (parseErrors) {
    result.diagnostics = diagText.empty() ? "error: parsing failed\n" : diagText;
    result.parseFailed = true;
    return result;
  }
  result.timingsMs["parse"] = MsSince(t0);
  for (auto& handle : handles) ParentsOfUserCodeOnly(handle.ast()->getASTContext());
  const std::set<std::string> inputs = InputsRead(handles);  // failed analyses too: an editor maps headers to classes
  result.inputs.assign(inputs.begin(), inputs.end());
  t0 = std::chrono::steady_clock::now();

  // Analyse: one pass over every AST, with its diagnostics printed against that AST's sources.
  ClassModel& model = result.model;
  model.forCpu = request.backend == Backend::Cpu || request.backend == Backend::Ispc;
  model.forIspc = request.backend == Backend::Ispc;
  model.virtualLevel = request.virtualLevel;
  const std::string unqualified = request.className.substr(request.className.rfind(':') == std::string::npos ? 0 : request.className.rfind(':') + 1);
  model.generatedName = !request.generatedName.empty() ? request.generatedName
                        : unqualified + (request.backend == Backend::Vulkan ? "_Vulkan" : request.backend == Backend::Ispc ? "_ISPC" : "_CPU");
  model.symbolPrefix = !request.generatedName.empty() ? request.generatedName : unqualified;
  model.megakernelByDefault = request.megakernel;
  model.templateDir = request.templateDir;
  unsigned errors = 0;
  auto forEachAst = [&](auto&& pass) {
    for (auto& handle : handles) {
      ParsedFile* ast = handle.ast();
      size_t before = handle.diagnostics().size();
      handle.printer().BeginSourceFile(ast->getLangOpts(), &ast->getPreprocessor());
      Reporter reporter(ast->getDiagnostics());
      // A CPU class runs the user's C++ as written; ISPC kernels have the GPU's rules (and their own).
      reporter.SetGpuRules(request.backend != Backend::Cpu);
      reporter.SetRecordingRules(request.backend == Backend::Vulkan);
      pass(*ast, reporter);
      errors += reporter.Errors();
      handle.printer().EndSourceFile();
      diagText += handle.diagnostics().substr(before) + reporter.Notes();
    }
  };
  try {
    forEachAst([&](ParsedFile& file, Reporter& rep) {
      AnalyzeTranslationUnit(file.getASTContext(), file.Includes(), request.className, compositions, rep, model);
    });
    // Composition: the implementations' code, printed from the AST that defines their methods (a CPU
    // class calls the interface as written; an ISPC class's loop nests call the printed code).
    if (errors == 0 && request.backend != Backend::Cpu && !model.compositions.empty())
      forEachAst([&](ParsedFile& file, Reporter& rep) { ComposeFromTranslationUnit(file.getASTContext(), rep, model); });
  } catch (const std::exception& e) {  // a template the analysis fills (dispatchers, traces) is missing or malformed
    result.diagnostics = diagText + "error: " + e.what() + "\n";
    return result;
  }
  if (errors > 0) {
    result.diagnostics = diagText;
    return result;
  }
  if (std::string problem = WholeClassProblems(request, model, sources.front()); !problem.empty()) {
    result.diagnostics = diagText + problem;
    return result;
  }
  FinishModel(model);  // the class data layout, the megakernels' merged code
  result.timingsMs["analyze"] = MsSince(t0);

  result.diagnostics = diagText;  // warnings, if any
  result.ok = true;
  return result;
}

TranslateResult Translate(const TranslateRequest& request, AstCache* cache, SpirvCache* spirvCache, ClassModel* modelOut) {
  TranslateResult result;
  AnalyzeResult analysis = Analyze(request, cache);
  result.diagnostics = analysis.diagnostics;
  result.timingsMs = analysis.timingsMs;
  result.parseFailed = analysis.parseFailed;
  result.inputs = analysis.inputs;
  if (!analysis.ok) return result;
  const ClassModel& model = analysis.model;
  if (modelOut) *modelOut = model;
  const bool vulkan = request.backend == Backend::Vulkan;
  GenerateOptions options;
  options.templateDir = request.templateDir;
  options.headerName = llvm::sys::path::filename(model.headerFile).str();
  options.headerInclude = IncludeSpelling(model.headerFile, request.compileArgs);
  options.includeSpelling = [&](const std::string& header) { return IncludeSpelling(header, request.compileArgs); };
  try {
    // Generate: the host code of the class, and for Vulkan its shaders.
    auto t0 = std::chrono::steady_clock::now();
    result.files = GenerateHost(model, options, vulkan);
    std::vector<ShaderSource> shaders;
    if (vulkan) shaders = GenerateShaders(model, options);
    // Lay out: C++ and GLSL as the project's own code looks (clang-format: whitespace only).
    for (auto& [name, text] : result.files) text = FormattedGeneratedCode(text);
    if (request.backend == Backend::Ispc) result.files[model.generatedName + "_kernels.ispc"] = GenerateIspcKernels(model, options);
    for (auto& shader : shaders) shader.glsl = FormattedGeneratedCode(shader.glsl);
    for (auto& shader : shaders) result.files["shaders/" + shader.name + "." + shader.stage] = shader.glsl;
    result.timingsMs["generate"] = MsSince(t0);
    // Compile: SPIR-V, embedded in the class's _shaders.cpp.
    t0 = std::chrono::steady_clock::now();
    if (vulkan) result.files[model.generatedName + "_shaders.cpp"] = CompileShaders(model.symbolPrefix, shaders, spirvCache, AllowsContraction(request.compileArgs));
    if (vulkan) result.timingsMs["spirv"] = MsSince(t0);
    // Level 3 asked for callable shaders: say which kernels' virtual calls still switch over classes.
    if (vulkan && model.virtualLevel == 3)
      for (const Kernel* k : VulkanKernels(model))
        if (!k->callables.empty() && !RunsCallables(*k))
          result.diagnostics += options.headerName + ": note: virtual level 3: " + model.className + "::" + k->name +
                                "'s virtual calls switch over the classes in its compute shader, not through callable shaders: " +
                                WhyNoCallables(*k) + "\n";
  } catch (const std::exception& e) {
    result.diagnostics += "error: " + std::string(e.what()) + "\n";
    result.files.clear();
    return result;
  }
  // Inputs: every file the ASTs read, and the templates (editing one regenerates).
  for (const char* t : {"glsl/kernel.comp.mustache", "glsl/reduce.comp.mustache", "glsl/ray_query.glsl.mustache", "glsl/dispatcher.glsl.mustache",
                        "glsl/callable_dispatcher.glsl.mustache", "glsl/callable_payload.glsl.mustache",
                        "glsl/leaf_trace.glsl.mustache", "glsl/virtual_objects.glsl.mustache",
                        "glsl/texture_array.glsl.mustache", "glsl/stage.glsl.mustache", "vulkan/class.h.mustache",
                        "vulkan/class.cpp.mustache", "cpu/class.h.mustache", "cpu/class.cpp.mustache", "ispc/kernels.ispc.mustache"})
    result.inputs.push_back(request.templateDir + "/" + t);
  std::sort(result.inputs.begin(), result.inputs.end());
  result.inputs.erase(std::unique(result.inputs.begin(), result.inputs.end()), result.inputs.end());
  result.ok = true;
  return result;
}

}  // namespace crossrt::engine
