// Helpers for translator tests: write a small class to a temporary folder, run the engine or
// the real crossrt command on it.
#pragma once
#include "Translator.h"

#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>

namespace fs = std::filesystem;

// Text without its whitespace and comment markers. The translator lays generated files out with
// clang-format, which may break or join lines between any two tokens and rewrap a long comment
// (adding `//` to its new lines): tests look for the tokens and the comments' words.
inline std::string Squeezed(const std::string& text)
{
  std::string out;
  for (size_t i = 0; i < text.size(); ++i)
  {
    if (text.compare(i, 2, "//") == 0)
      ++i;
    else if (text[i] != ' ' && text[i] != '\n' && text[i] != '\t')
      out += text[i];
  }
  return out;
}

struct TempClass
{
  fs::path dir;
  TempClass(const std::string& name, const std::string& header, const std::string& source)
  {
    dir = fs::temp_directory_path() / ("crossrt-test-" + name + "-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / (name + ".h")) << header;
    std::ofstream(dir / (name + ".cpp")) << source;
  }
  ~TempClass() { std::error_code ec; fs::remove_all(dir, ec); }
  std::string Source(const std::string& name) const { return (dir / (name + ".cpp")).string(); }
  std::string Header(const std::string& name) const { return (dir / (name + ".h")).string(); }
};

inline crossrt::engine::TranslateRequest MakeRequest(const TempClass& tc, const std::string& name,
                                                     crossrt::engine::Backend backend = crossrt::engine::Backend::Vulkan)
{
  crossrt::engine::TranslateRequest r;
  r.className = name;
  r.backend = backend;
  r.sources = {tc.Source(name)};
  r.compileArgs = {"-I" CROSSRT_SOURCE_DIR "/libs/litemath", "-I" + tc.dir.string()};
  r.outputDir = (tc.dir / "out").string();
  r.templateDir = CROSSRT_SOURCE_DIR "/templates";
  return r;
}

// The model's member or control function of that name (the test fails when there is none).
inline const crossrt::engine::Member& MemberNamed(const crossrt::engine::ClassModel& model, const std::string& name)
{
  for (auto& m : model.members)
    if (m.name == name) return m;
  FAIL("no member " << name);
  throw;
}
inline const crossrt::engine::Control& ControlNamed(const crossrt::engine::ClassModel& model, const std::string& name)
{
  for (auto& c : model.controls)
    if (c.name == name) return c;
  FAIL("no control function " << name);
  throw;
}

struct CommandResult { int exitCode = -1; bool crashed = false; std::string output; };

// Runs the crossrt command (stderr merged into the captured output). Safe to call from threads.
inline CommandResult RunCrossrt(const std::string& args)
{
  CommandResult r;
  FILE* p = ::popen((std::string(CROSSRT_CLIENT) + " " + args + " 2>&1").c_str(), "r");
  if (!p) {
    r.output = "popen failed";
    return r;
  }
  char buf[4096];
  size_t got;
  while ((got = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, got);
  int status = ::pclose(p);
  r.crashed = WIFSIGNALED(status);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}
