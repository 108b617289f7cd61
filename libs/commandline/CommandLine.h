// One command line for CrossRT's programs (the examples, the benchmarks, the test drivers): CLI11,
// set up the same way everywhere, so that every program answers --help with a "usage:" line and its
// options with their defaults, and refuses a bad value or an unknown option with one line naming
// it and exit status 2. Internal to this project: users' programs get nothing from it.
#pragma once
#include <CLI/CLI.hpp>

#include <climits>
#include <cstdio>
#include <string>

namespace crossrt {

// A program named `name` that does `description`: lower-case "usage:", defaults shown.
struct CommandLine : CLI::App
{
  CommandLine(const std::string& name, const std::string& description) : CLI::App(description, name)
  {
    get_formatter()->label("Usage", "usage");
    get_formatter()->column_width(28);
    option_defaults()->always_capture_default();
  }
};

// Integer options that must be at least 1, or at least 0 (CLI11's own checks allow any double).
inline CLI::Validator Positive() { return CLI::Range(1, INT_MAX).description("POSITIVE"); }
inline CLI::Validator NonNegative() { return CLI::Range(0, INT_MAX).description("NON-NEGATIVE"); }

// Parses argv into the options: -1 to go on, or the status to exit with (0 after --help, 2 after
// an error, which is printed as "<program>: <what> (see --help)").
inline int ParseCommandLine(CLI::App& app, int argc, char** argv)
{
  try
  {
    app.parse(argc, argv);
    return -1;
  }
  catch (const CLI::CallForHelp&)
  {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  }
  catch (const CLI::ParseError& e)
  {
    std::fprintf(stderr, "%s: %s (see --help)\n", app.get_name().c_str(), e.what());
    return 2;
  }
}

}  // namespace crossrt
