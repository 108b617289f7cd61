// What each _ISPC kernel's LaneChoice measured, kept from one run of a program to the next (header
// only). A kernel's first calls in a run would otherwise always run in SIMD lanes, and a program
// that calls a kernel once or twice (a BVH built once) would always get the lanes, slower or not: on
// an AMD EPYC (Zen 4) with AVX2 the LBVH build's lanes took 2-4x its scalar loop's time in five
// kernels of seven, so a program's one LBVH_ISPC build took about twice LBVH_CPU's.
//
// So at exit each LaneChoice hands its means (per size class; a way's first call where it ran only
// once) to LaneMemory, which writes them to a file; in the next run, a kernel's first call takes
// the way that was faster then, in the size class of the last call then, or, where one way has no
// time yet, that way. The other way is tried after 16 calls as usual (on the next call where its
// remembered mean is within a quarter of the verdict's: MeasuredWays::kCloseToVerdict), so that in
// a program that calls a kernel often a stale verdict (a new CPU under the same name, a changed
// kernel, another workload) corrects itself. A program that calls a kernel once runs it in lanes
// in its first run, as its scalar loop in its second, and from its third the way whose first call
// was faster, the other again in every 16th run.
//
// The file: CROSSRT_LANE_MEMORY if set (`off`: nothing is read or written), else
// $XDG_CACHE_HOME/crossrt/lane-choices.tsv, else $HOME/.cache/crossrt/lane-choices.tsv. A line per
// kernel and size class, tab-separated: the machine (CPU model, ISPC target, threads), the kernel
// (Class::kernel), the size class, the lanes' and the scalar loop's mean ms per iteration (-1 for a
// way that has not run), 1 on the size class of the kernel's last call, and the runs in a row that
// ran only the faster way (in the 16th the other is tried again). Lines of other
// machines are kept, the oldest dropped past kMaxLines. A file that cannot be read or written only
// costs the measuring again (CROSSRT_ISPC_LANES_LOG=1 says so); two programs that exit at once
// each replace the file whole (written beside it, then renamed), and the later one's measurements
// win.
#pragma once
#include "IspcTargets.h"

#include <sched.h>
#include <unistd.h>
#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace crossrt {

// A kernel's means in one size class (LoopSizeClass), as a run left them.
struct RememberedWays {
  int sizeClass;
  float lanesMs, scalarMs;  // mean ms per iteration (or the first call's, where that was the only one), -1 where that way did not run
  bool last;                // the size class of the kernel's last call
  int verdictOnlyRuns = 0;  // runs in a row that ran only the faster way (every 16th tries the other)
};

class LaneMemory {
 public:
  static constexpr size_t kMaxLines = 4096;

  // The one memory of the program. A LaneChoice asks for it when it is made, so that it is made
  // first and outlives every LaneChoice (statics end in the reverse order they were made).
  static LaneMemory& Get() {
    static LaneMemory memory;
    return memory;
  }

  // The file, or "" where CROSSRT_LANE_MEMORY is `off` or no cache folder is known.
  static std::string Path() {
    if (const char* set = std::getenv("CROSSRT_LANE_MEMORY"); set && *set) return std::strcmp(set, "off") == 0 ? "" : set;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/crossrt/lane-choices.tsv";
    if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/crossrt/lane-choices.tsv";
    return "";
  }

  // What an earlier run measured for `kernel` on this machine (empty where nothing).
  std::vector<RememberedWays> Recall(const std::string& kernel) {
    std::lock_guard<std::mutex> lock(m_mutex);
    const auto found = m_recalled.find(kernel);
    return found == m_recalled.end() ? std::vector<RememberedWays>{} : found->second;
  }

  // What this run measured for `kernel`, written at exit.
  void Remember(const std::string& kernel, std::vector<RememberedWays> ways) {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_measured[kernel] = std::move(ways);
  }

  // Reads the file again, where the environment names it now (the memory is read as the program
  // starts: a test that sets CROSSRT_LANE_MEMORY later calls this). What this run measured stays.
  void Reload() {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_path = Path();
    Read();
  }

  // Writes what this run measured, merged into the file as it is now. False where it could not.
  bool Save() {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_measured.empty() || m_path.empty()) return true;
    std::vector<std::string> kept;
    for (const Line& line : ReadLines(m_path))
      if (line.machine != m_machine || !m_measured.count(line.kernel)) kept.push_back(line.text);
    // The oldest lines go first where the file would pass kMaxLines (a differential soak's
    // thousands of random classes, each run once).
    size_t total = kept.size();
    for (const auto& [kernel, ways] : m_measured) total += ways.size();
    std::ostringstream text;
    for (size_t k = total > kMaxLines ? std::min(kept.size(), total - kMaxLines) : 0; k < kept.size(); ++k) text << kept[k] << '\n';
    for (const auto& [kernel, ways] : m_measured)
      for (const RememberedWays& w : ways)
        text << m_machine << '\t' << kernel << '\t' << w.sizeClass << '\t' << (w.lanesMs > 0.0f ? w.lanesMs : -1.0f) << '\t'
             << (w.scalarMs > 0.0f ? w.scalarMs : -1.0f) << '\t' << (w.last ? 1 : 0) << '\t' << w.verdictOnlyRuns << '\n';
    std::error_code error;
    const std::filesystem::path file(m_path);
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), error);
    const std::string beside = m_path + ".tmp" + std::to_string(getpid());
    {
      std::ofstream out(beside, std::ios::trunc);
      out << text.str();
      if (!out.flush()) return Failed("could not write " + beside);
    }
    std::filesystem::rename(beside, file, error);
    if (error) {
      std::filesystem::remove(beside, error);
      return Failed("could not replace " + m_path);
    }
    m_measured.clear();
    return true;
  }

  ~LaneMemory() { Save(); }

  // This machine, as the file names it: the CPU's model, the ISPC target the kernels run, and the
  // threads the program may use.
  static std::string Machine() {
    // The brand string CPUID gives (/proc/cpuinfo's "model name"), read at once: /proc/cpuinfo
    // takes a while to read on a machine of many cores, and this is a kernel's first call.
    std::string model = "unknown CPU";
#if defined(__x86_64__) || defined(__i386__)
    unsigned int words[12] = {};
    if (__get_cpuid_max(0x80000000u, nullptr) >= 0x80000004u) {
      for (unsigned int leaf = 0; leaf < 3; ++leaf)
        __get_cpuid(0x80000002u + leaf, &words[4 * leaf], &words[4 * leaf + 1], &words[4 * leaf + 2], &words[4 * leaf + 3]);
      char brand[sizeof words + 1] = {};
      std::memcpy(brand, words, sizeof words);
      model = brand;
      model.erase(0, model.find_first_not_of(' '));
      model.erase(model.find_last_not_of(' ') + 1);
      if (model.empty()) model = "unknown CPU";
    }
#endif
    const std::string target = IspcTargetInUse();
    // The threads this program may run on (its affinity: one system call, where the machine's count
    // reads /sys): the means are of loops on all of them.
    cpu_set_t cores;
    CPU_ZERO(&cores);
    const int threads = sched_getaffinity(0, sizeof cores, &cores) == 0 ? CPU_COUNT(&cores) : int(std::thread::hardware_concurrency());
    std::string machine = model + ", " + target + ", " + std::to_string(threads) + " threads";
    for (char& c : machine)
      if (c == '\t' || c == '\n') c = ' ';
    return machine;
  }

 private:
  struct Line {
    std::string text, machine, kernel;
    RememberedWays ways;
  };

  LaneMemory() : m_path(Path()), m_machine(Machine()) { Read(); }

  void Read() {
    m_recalled.clear();
    if (m_path.empty()) return;
    for (const Line& line : ReadLines(m_path))
      if (line.machine == m_machine) m_recalled[line.kernel].push_back(line.ways);
  }

  // The file's well-formed lines (a line that is not is dropped: the next save leaves it out). Read
  // with stdio: a program's first use of iostreams costs a tenth of a millisecond, at its first
  // kernel call.
  static std::vector<Line> ReadLines(const std::string& path) {
    std::vector<Line> lines;
    std::FILE* in = std::fopen(path.c_str(), "r");
    if (!in) return lines;
    char* buffer = nullptr;
    size_t capacity = 0;
    for (ssize_t length; (length = getline(&buffer, &capacity, in)) >= 0;) {
      std::string text(buffer, size_t(length));
      if (!text.empty() && text.back() == '\n') text.pop_back();
      Line line{text, "", "", {}};
      std::vector<std::string> fields;
      for (size_t start = 0;;) {
        const size_t tab = text.find('\t', start);
        fields.push_back(text.substr(start, tab == std::string::npos ? std::string::npos : tab - start));
        if (tab == std::string::npos) break;
        start = tab + 1;
      }
      if (fields.size() != 7) continue;
      char* end = nullptr;
      line.machine = fields[0];
      line.kernel = fields[1];
      const long sizeClass = std::strtol(fields[2].c_str(), &end, 10);
      if (*end != '\0' || sizeClass < 0 || sizeClass >= 64) continue;
      const float lanes = std::strtof(fields[3].c_str(), &end);
      if (*end != '\0' || !(lanes > 0.0f || lanes == -1.0f)) continue;
      const float scalar = std::strtof(fields[4].c_str(), &end);
      if (*end != '\0' || !(scalar > 0.0f || scalar == -1.0f) || !(lanes > 0.0f || scalar > 0.0f)) continue;
      if (fields[5] != "0" && fields[5] != "1") continue;
      const long runs = std::strtol(fields[6].c_str(), &end, 10);
      if (*end != '\0' || fields[6].empty() || runs < 0 || runs > 1000000) continue;
      line.ways = {int(sizeClass), lanes, scalar, fields[5] == "1", int(runs)};
      lines.push_back(line);
    }
    std::free(buffer);
    std::fclose(in);
    return lines;
  }

  static bool Failed(const std::string& what) {
    const char* logged = std::getenv("CROSSRT_ISPC_LANES_LOG");
    if (logged && std::strcmp(logged, "1") == 0)
      std::fprintf(stderr, "crossrt: the lane choices are not remembered for the next run: %s\n", what.c_str());
    return false;
  }

  std::mutex m_mutex;
  std::string m_path;
  const std::string m_machine;
  std::map<std::string, std::vector<RememberedWays>> m_recalled, m_measured;  // by kernel
};

}  // namespace crossrt
