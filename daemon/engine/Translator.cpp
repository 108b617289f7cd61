#include "Translator.h"

#include "Analysis.h"
#include "AstCache.h"
#include "Canonical.h"
#include "CodeGen.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <clang/Basic/DiagnosticOptions.h>
#include <clang/Basic/SourceManager.h>
#include <clang/Frontend/ASTUnit.h>
#include <clang/Frontend/TextDiagnosticPrinter.h>
#include <clang/Tooling/CompilationDatabase.h>
#include <clang/Tooling/Tooling.h>
#include <llvm/Support/FileSystem.h>
#include <llvm/Support/Path.h>
#include <llvm/Support/raw_ostream.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <cstdlib>
#include <mutex>
#include <chrono>
#include <regex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#ifndef CROSSRT_CLANG_RESOURCE_DIR
#error "CROSSRT_CLANG_RESOURCE_DIR must point at Clang's resource directory (stddef.h and friends)"
#endif

namespace crossrt::engine {

void LinkSizeAttribute();

namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// How generated code includes the user's header: relative to an include directory when one
// contains it (keeps the output independent of where the tree lives), else by absolute path.
std::string IncludeSpelling(const std::string& header, const std::vector<std::string>& args) {
  std::string best;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string dir;
    if (args[i] == "-I" || args[i] == "-isystem") { if (i + 1 < args.size()) dir = args[i + 1]; }
    else if (args[i].rfind("-I", 0) == 0) dir = args[i].substr(2);
    if (dir.empty()) continue;
    llvm::SmallString<256> abs(dir);
    llvm::sys::fs::make_absolute(abs);
    llvm::sys::path::remove_dots(abs, true);
    std::string prefix = std::string(abs.str()) + "/";
    if (header.rfind(prefix, 0) == 0 && (best.empty() || header.size() - prefix.size() < best.size()))
      best = header.substr(prefix.size());
  }
  return best.empty() ? header : best;
}

// Compiles one GLSL shader of `stage` (comp, rgen, rcall, rint, rchit or rmiss) to SPIR-V in-process with the glslang
// library (as `glslangValidator -V --target-env vulkan1.2` would); returns the words or throws.
std::vector<uint32_t> CompileGlsl(const std::string& name, const std::string& glsl, const std::string& stage) {
  static std::mutex mutex;  // glslang keeps global state: one compile at a time (a few ms each)
  std::lock_guard<std::mutex> guard(mutex);
  static bool initialized = glslang::InitializeProcess();
  (void)initialized;
  static const std::map<std::string, EShLanguage> stages = {{"comp", EShLangCompute}, {"rgen", EShLangRayGen}, {"rcall", EShLangCallable},
                                                            {"rint", EShLangIntersect}, {"rchit", EShLangClosestHit}, {"rmiss", EShLangMiss}};
  const EShLanguage language = stages.at(stage);
  glslang::TShader shader(language);
  const char* text = glsl.c_str();
  const char* fileName = name.c_str();
  shader.setStringsWithLengthsAndNames(&text, nullptr, &fileName, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, language, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
  const EShMessages messages = EShMessages(EShMsgSpvRules | EShMsgVulkanRules);
  glslang::TProgram program;
  bool ok = shader.parse(GetDefaultResources(), 460, false, messages);
  if (ok) {
    program.addShader(&shader);
    ok = program.link(messages);
  }
  if (!ok) {
    // Quote the generated lines the messages point at, so that a report carries what went wrong.
    std::string log = std::string(shader.getInfoLog()) + program.getInfoLog(), quoted;
    std::vector<std::string> lines;
    std::istringstream glslLines(glsl);
    for (std::string line; std::getline(glslLines, line);) lines.push_back(line);
    const std::string marker = name + ":";
    for (size_t at = log.find(marker); at != std::string::npos; at = log.find(marker, at + 1)) {
      size_t lineNo = std::strtoul(log.c_str() + at + marker.size(), nullptr, 10);
      if (lineNo >= 1 && lineNo <= lines.size())
        quoted += "  " + std::to_string(lineNo) + " | " + lines[lineNo - 1] + "\n";
    }
    throw std::runtime_error("internal error: the GLSL generated for '" + name + "' does not compile (please report it):\n" +
                             log + quoted);
  }
  std::vector<uint32_t> words;
  glslang::SpvOptions options;
  options.validate = true;
  glslang::GlslangToSpv(*program.getIntermediate(language), words, &options);
  return words;
}

std::string EmbedSpirv(const std::string& className, const std::vector<std::pair<std::string, std::vector<uint32_t>>>& shaders) {
  std::ostringstream os;
  os << "// SPIR-V of the kernels of " << className << "_Vulkan, compiled from shaders/ by glslang.\n"
     << "// Generated by CrossRT; rewritten on every build.\n#include <cstddef>\n#include <cstdint>\n";
  for (auto& [kernel, words] : shaders) {
    // Named after the class too: two classes may have kernels of the same name in one program.
    const std::string name = className + "_" + kernel;
    os << "\nextern const uint32_t " << name << "_spv[];\nextern const size_t " << name << "_spvBytes;\n";
    os << "const uint32_t " << name << "_spv[] = {";
    for (size_t i = 0; i < words.size(); ++i) {
      if (i % 8 == 0) os << "\n  ";
      char buf[16];
      std::snprintf(buf, sizeof buf, "0x%08x,", words[i]);
      os << buf << (i % 8 == 7 ? "" : " ");
    }
    os << "\n};\nconst size_t " << name << "_spvBytes = sizeof(" << name << "_spv);\n";
  }
  return os.str();
}

// The target's flags that change what the class means to Clang: include paths, macros, the
// language standard, target and feature flags. The rest (warnings, optimisation, GCC-only
// spellings) is dropped: the class is only parsed, and an unknown flag would stop Clang.
bool KeepFlag(const std::string& a) {
  static const char* prefixes[] = {"-D", "-U", "-I", "-std=", "-m", "-isystem", "-iquote", "-include", "-fopenmp",
                                   "-fno-exceptions", "-fno-rtti", "-fexceptions", "-frtti", "-fchar8_t", "-fno-char8_t"};
  for (const char* p : prefixes)
    if (a.rfind(p, 0) == 0) return true;
  return false;
}

std::vector<std::string> FilterFlags(const std::vector<std::string>& in) {
  std::vector<std::string> out;
  // The language standard: the highest of -std=c++NN and CMake's cxx_std_NN compile features.
  int standard = 0;
  for (auto& a : in) {
    std::string digits = a.rfind("-std=c++", 0) == 0 ? a.substr(8) : a.rfind("-std=gnu++", 0) == 0 ? a.substr(10)
                         : a.rfind("cxx_std_", 0) == 0 ? a.substr(8) : "";
    if (!digits.empty() && std::isdigit(static_cast<unsigned char>(digits[0]))) standard = std::max(standard, std::atoi(digits.c_str()));
  }
  if (standard > 0) out.push_back("-std=c++" + std::to_string(standard));
  for (size_t i = 0; i < in.size(); ++i) {
    const std::string& a = in[i];
    if (a.rfind("-std=", 0) == 0) continue;  // chosen above
    bool takesValue = a == "-I" || a == "-D" || a == "-U" || a == "-isystem" || a == "-iquote" || a == "-include";
    if (!KeepFlag(a)) continue;
    out.push_back(a);
    if (takesValue && i + 1 < in.size()) out.push_back(in[++i]);
  }
  return out;
}

// A source that includes a header the translation generates (PointStats_Vulkan.h), which does not
// exist yet: main.cpp, say, listed by mistake. Parsing it would bury the user in errors that follow
// from the missing header, so name the problem instead. Empty when there is none.
std::string GeneratedIncludeProblem(const std::string& source, const std::vector<std::string>& args) {
  static const std::regex generated(R"(^[ \t]*#[ \t]*include[ \t]*[<"](([^>"]*/)?\w+_(Vulkan|CPU|ISPC)\.h)[>"])");
  std::vector<std::string> dirs = {llvm::sys::path::parent_path(source).str()};
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "-I" && i + 1 < args.size()) dirs.push_back(args[i + 1]);
    else if (args[i].rfind("-I", 0) == 0 && args[i].size() > 2) dirs.push_back(args[i].substr(2));
  }
  std::ifstream in(source);
  unsigned lineNo = 0;
  for (std::string line; std::getline(in, line);) {
    ++lineNo;
    std::smatch m;
    if (!std::regex_search(line, m, generated)) continue;
    const std::string name = m[1].str();
    if (std::any_of(dirs.begin(), dirs.end(), [&](const std::string& d) { return llvm::sys::fs::exists(d + "/" + name); })) continue;
    const std::string file = llvm::sys::path::filename(source).str();
    return source + ":" + std::to_string(lineNo) + ":" + std::to_string(m.position(1) + 1) + ": error: " + file + " includes '" + name +
           "', a header that translations generate, so it cannot be parsed to translate a class\n"
           "note: hint: list only the files that define the class's member functions in SOURCES, or leave SOURCES out and "
           "crossrt_add_class finds them\n";
  }
  return "";
}

}  // namespace

std::vector<std::string> ParseArguments(const TranslateRequest& request) {
  std::vector<std::string> args = {"-xc++", "-fsyntax-only", "-D__CROSSRT__=1", "-Wno-unused-command-line-argument"};
  auto kept = FilterFlags(request.compileArgs);
  bool hasStandard = std::any_of(kept.begin(), kept.end(), [](const std::string& a) { return a.rfind("-std=", 0) == 0; });
  if (!hasStandard) args.push_back("-std=c++17");  // the least the LiteMath headers need
  args.insert(args.end(), kept.begin(), kept.end());
  return args;
}

AnalyzeResult Analyze(const TranslateRequest& request, AstCache* sharedCache) {
  LinkSizeAttribute();
  AnalyzeResult result;
  std::vector<std::string> sources;
  for (auto& s : request.sources) {
    llvm::SmallString<256> abs(s);
    llvm::sys::fs::make_absolute(abs);
    llvm::sys::path::remove_dots(abs, true);
    if (!llvm::sys::fs::exists(abs)) {
      result.diagnostics += "error: source file '" + s + "' does not exist\n";
      return result;
    }
    sources.push_back(std::string(abs));
  }
  // One handle per file, always locked in the same order: no self- or cross-request deadlock.
  std::sort(sources.begin(), sources.end());
  sources.erase(std::unique(sources.begin(), sources.end()), sources.end());
  if (sources.empty()) {
    result.diagnostics = "error: no source files given for class '" + request.className + "'\n";
    return result;
  }

  AstCache localCache(sources.size());
  AstCache& cache = sharedCache ? *sharedCache : localCache;
  const std::vector<std::string> args = ParseArguments(request);
  for (auto& s : sources)
    if (std::string problem = GeneratedIncludeProblem(s, args); !problem.empty()) {
      result.diagnostics = problem;
      return result;
    }
  auto t0 = std::chrono::steady_clock::now();
  std::vector<AstCache::Handle> handles;
  std::string diagText;
  bool parseErrors = false;
  for (auto& s : sources) {
    handles.push_back(cache.Get(s, args));
    diagText += handles.back().diagnostics();
    parseErrors |= handles.back().failed();
  }
  if (parseErrors) {
    result.diagnostics = diagText.empty() ? "error: parsing failed\n" : diagText;
    return result;
  }
  std::vector<clang::ASTUnit*> asts;
  for (auto& h : handles) asts.push_back(h.ast());
  result.timingsMs["parse"] = MsSince(t0);
  t0 = std::chrono::steady_clock::now();

  // Every file the ASTs read is an input of the translation (for depfiles and cache keys), by
  // its real path: Clang reaches the GCC headers as /../lib/gcc/<triple>/12/../../../../include,
  // which a build tool shortens without following /lib -> /usr/lib to a file that does not
  // exist, and then rebuilds on every run.
  std::set<std::string> inputs;
  for (auto* ast : asts) {
    auto& sm = ast->getSourceManager();
    for (auto it = sm.fileinfo_begin(); it != sm.fileinfo_end(); ++it) {
      std::error_code ec;
      const std::string name = it->first.getName().str();
      const std::filesystem::path real = std::filesystem::weakly_canonical(name, ec);
      inputs.insert(ec ? name : real.string());
    }
  }

  std::map<std::string, std::string> compositions;
  for (auto& c : request.compositions) {
    auto eq = c.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == c.size()) {
      result.diagnostics = "error: composition '" + c + "' is not of the form Interface=Implementation (e.g. ISceneObject=BVHScene)\n";
      return result;
    }
    compositions[c.substr(0, eq)] = c.substr(eq + 1);
  }
  ClassModel& model = result.model;
  model.forCpu = request.backend == Backend::Cpu;
  model.virtualLevel = request.virtualLevel;
  model.megakernelByDefault = request.megakernel;
  unsigned errors = 0;
  // Runs one analysis step per AST with its diagnostics printed against that AST's sources.
  auto forEachAst = [&](auto&& step) {
    for (auto& handle : handles) {
      clang::ASTUnit* ast = handle.ast();
      size_t before = handle.diagnostics().size();
      handle.printer().BeginSourceFile(ast->getLangOpts(), &ast->getPreprocessor());
      Reporter reporter(ast->getDiagnostics());
      reporter.SetGpuRules(request.backend == Backend::Vulkan);  // a CPU class runs the user's C++ as written
      step(ast->getASTContext(), reporter);
      errors += reporter.Errors();
      handle.printer().EndSourceFile();
      diagText += handle.diagnostics().substr(before) + reporter.Notes();
    }
  };
  forEachAst([&](clang::ASTContext& ctx, Reporter& reporter) {
    AnalyzeTranslationUnit(ctx, request.className, compositions, reporter, model);
  });
  // Composed implementations are printed from the AST that defines their methods.
  if (errors == 0 && !model.compositions.empty() && request.backend == Backend::Vulkan) {  // a CPU class calls the interface as written
    forEachAst([&](clang::ASTContext& ctx, Reporter& reporter) { ComposeFromTranslationUnit(ctx, reporter, model); });
    for (auto& comp : model.compositions)
      if (errors == 0 && comp.implHeader.empty()) {
        diagText += "error: " + request.className + "'s kernels call " + comp.interfaceName + " through '" + comp.holder +
                    "', composed as " + comp.implName + ", but no source file defines class " + comp.implName +
                    " with the bodies of the methods they call\nnote: hint: list the implementation's source file (e.g. BVHScene.cpp) in crossrt_add_class(... SOURCES ...)\n";
        ++errors;
      }
  }
  if (model.className.empty()) {
    result.diagnostics = diagText + "error: class '" + request.className + "' is not defined in " + sources.front() +
                         " or the headers it includes\nnote: hint: check the name given to crossrt_add_class; name a class in a namespace with it (demo::Render)\n";
    return result;
  }
  if (model.kernels.empty() && errors == 0) {
    result.diagnostics = diagText + model.headerFile + ": error: class '" + request.className +
                         "' has no kernels\nnote: hint: kernels are member functions named kernel1D_*, kernel2D_*, kernel3D_* (holding loops) or kernel_* (taking tid)\n";
    return result;
  }
  if (errors > 0) {
    result.diagnostics = diagText;
    return result;
  }
  FinishModel(model);
  result.timingsMs["analyze"] = MsSince(t0);
  result.inputs.assign(inputs.begin(), inputs.end());
  result.diagnostics = diagText;  // warnings, if any
  result.ok = true;
  return result;
}


bool SpirvCache::Find(const std::string& glsl, std::vector<uint32_t>& words) const {
  std::lock_guard<std::mutex> guard(m_mutex);
  auto it = m_byGlsl.find(glsl);
  if (it == m_byGlsl.end()) return false;
  words = it->second;
  return true;
}

void SpirvCache::Add(const std::string& glsl, const std::vector<uint32_t>& words) {
  std::lock_guard<std::mutex> guard(m_mutex);
  if (m_byGlsl.size() > 4096) m_byGlsl.clear();  // bounded: a few MiB at most
  m_byGlsl[glsl] = words;
}

size_t SpirvCache::Size() const {
  std::lock_guard<std::mutex> guard(m_mutex);
  return m_byGlsl.size();
}

TranslateResult Translate(const TranslateRequest& request, AstCache* cache, SpirvCache* spirvCache) {
  TranslateResult result;
  AnalyzeResult analysis = Analyze(request, cache);
  result.diagnostics = analysis.diagnostics;
  result.timingsMs = analysis.timingsMs;
  if (!analysis.ok) return result;
  const ClassModel& model = analysis.model;
  std::set<std::string> inputs(analysis.inputs.begin(), analysis.inputs.end());
  const std::string diagText = analysis.diagnostics;
  GenerateOptions options;
  options.templateDir = request.templateDir;
  options.headerName = llvm::sys::path::filename(model.headerFile).str();
  options.headerInclude = IncludeSpelling(model.headerFile, request.compileArgs);
  options.includeSpelling = [&](const std::string& header) { return IncludeSpelling(header, request.compileArgs); };
  try {
    auto t0 = std::chrono::steady_clock::now();
    bool vulkan = request.backend == Backend::Vulkan;
    result.files = GenerateHost(model, options, vulkan);
    std::vector<ShaderSource> shaders;
    if (vulkan) shaders = GenerateShaders(model, options);
    // Layout: the generated C++ and GLSL as the project's own code looks (clang-format changes
    // whitespace only, never a token).
    for (auto& [name, text] : result.files) text = FormattedGeneratedCode(text);
    for (auto& shader : shaders) shader.glsl = FormattedGeneratedCode(shader.glsl);
    result.timingsMs["generate"] = MsSince(t0);
    if (vulkan) {
      t0 = std::chrono::steady_clock::now();
      std::vector<std::pair<std::string, std::vector<uint32_t>>> spirv;
      for (auto& shader : shaders) {
        result.files["shaders/" + shader.name + "." + shader.stage] = shader.glsl;
        std::vector<uint32_t> words;
        if (!spirvCache || !spirvCache->Find(shader.glsl, words)) {
          words = CompileGlsl(shader.name, shader.glsl, shader.stage);
          if (spirvCache) spirvCache->Add(shader.glsl, words);
        }
        spirv.push_back({shader.name, words});
      }
      result.files[model.className + "_Vulkan_shaders.cpp"] = EmbedSpirv(model.className, spirv);
      result.timingsMs["spirv"] = MsSince(t0);
    }
  } catch (const std::exception& e) {
    result.diagnostics = diagText + "error: " + e.what() + "\n";
    result.files.clear();
    return result;
  }
  // Templates are inputs too: editing one regenerates.
  for (const char* t : {"glsl/kernel.comp.mustache", "glsl/reduce.comp.mustache", "glsl/ray_query.glsl.mustache", "glsl/texture_array.glsl.mustache",
                        "glsl/stage.glsl.mustache", "vulkan/class.h.mustache", "vulkan/class.cpp.mustache", "cpu/class.h.mustache",
                        "cpu/class.cpp.mustache"})
    inputs.insert(request.templateDir + "/" + t);
  result.inputs.assign(inputs.begin(), inputs.end());
  result.diagnostics = diagText;  // warnings, if any
  result.ok = true;
  return result;
}

}  // namespace crossrt::engine
