// crossrt: the command crossrt_add_class() runs. It translates one class into generated sources.
// The translation runs in-process; the translation daemon (cached ASTs) comes later and will sit
// behind the same command line.
#include "Translator.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

const char* kUsage =
    "usage: crossrt translate --class NAME --backend vulkan|cpu --out DIR --source FILE [--source FILE...]\n"
    "                         [--templates DIR] [--glslang PATH] [--depfile FILE --depfile-target FILE]\n"
    "                         [-- COMPILE_ARGS...]\n"
    "       crossrt --version\n";

int Usage(const std::string& message) {
  std::cerr << "crossrt: error: " << message << "\n" << kUsage;
  return 2;
}

// Make-style depfile: "target: input1 input2 ..." with spaces escaped.
bool WriteDepfile(const std::string& path, const std::string& target, const std::vector<std::string>& inputs) {
  auto escape = [](const std::string& s) {
    std::string out;
    for (char c : s) {
      if (c == ' ' || c == '#') out += '\\';
      if (c == '$') out += '$';
      out += c;
    }
    return out;
  };
  std::string text = escape(target) + ":";
  for (auto& in : inputs) text += " \\\n  " + escape(in);
  text += "\n";
  std::ifstream old(path);
  std::string previous((std::istreambuf_iterator<char>(old)), std::istreambuf_iterator<char>());
  if (previous == text) return true;
  std::ofstream out(path, std::ios::trunc);
  out << text;
  return out.good();
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) return Usage("no command given");
  if (args[0] == "--version") {
    std::cout << "crossrt " << crossrt::engine::TranslatorVersion() << "\n";
    return 0;
  }
  if (args[0] != "translate") return Usage("unknown command '" + args[0] + "'");

  crossrt::engine::TranslateRequest request;
  request.templateDir = CROSSRT_DEFAULT_TEMPLATE_DIR;
  std::string depfile, depfileTarget, backend;
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--") {
      request.compileArgs.assign(args.begin() + i + 1, args.end());
      break;
    }
    if (i + 1 >= args.size()) return Usage("option '" + a + "' needs a value");
    const std::string& v = args[++i];
    if (a == "--class") request.className = v;
    else if (a == "--backend") backend = v;
    else if (a == "--out") request.outputDir = v;
    else if (a == "--source") request.sources.push_back(v);
    else if (a == "--templates") request.templateDir = v;
    else if (a == "--glslang") request.glslangValidator = v;
    else if (a == "--depfile") depfile = v;
    else if (a == "--depfile-target") depfileTarget = v;
    else return Usage("unknown option '" + a + "'");
  }
  if (request.className.empty()) return Usage("--class is required");
  if (request.outputDir.empty()) return Usage("--out is required");
  if (request.sources.empty()) return Usage("at least one --source is required");
  if (backend == "vulkan") request.backend = crossrt::engine::Backend::Vulkan;
  else if (backend == "cpu") request.backend = crossrt::engine::Backend::Cpu;
  else return Usage("--backend must be 'vulkan' or 'cpu', not '" + backend + "'");

  crossrt::engine::TranslateResult result;
  try {
    result = crossrt::engine::Translate(request);
  } catch (const std::exception& e) {
    std::cerr << "crossrt: internal error while translating '" << request.className << "': " << e.what() << "\n";
    return 1;
  }
  std::cerr << result.diagnostics;
  if (!result.ok) {
    std::cerr << "crossrt: translation of class '" << request.className << "' failed\n";
    return 1;
  }
  try {
    crossrt::engine::WriteOutputs(request, result);
  } catch (const std::exception& e) {
    std::cerr << "crossrt: error: " << e.what() << "\n";
    return 1;
  }
  if (!depfile.empty() && !WriteDepfile(depfile, depfileTarget.empty() ? depfile : depfileTarget, result.inputs)) {
    std::cerr << "crossrt: error: cannot write depfile '" << depfile << "'\n";
    return 1;
  }
  return 0;
}
