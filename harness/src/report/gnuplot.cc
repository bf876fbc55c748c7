#include "gnuplot.h"

#include "text.h"

#include "mechbench/harness/output.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

extern char** environ;

namespace mechbench::harness::report {

namespace fs = std::filesystem;

namespace {

struct ProcResult {
  bool started = false;
  bool timed_out = false;
  int exit_code = -1;
  std::string why;  // when not started
};

ProcResult RunProcess(const std::vector<std::string>& args, const fs::path& out, const fs::path& err,
                      double timeout_seconds) {
  ProcResult r;
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, copy[0].c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    r.why = "cannot start " + args[0] + ": " + std::strerror(rc);
    return r;
  }
  r.started = true;
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  for (;;) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) {
      r.why = std::string("waitpid: ") + std::strerror(errno);
      return r;
    }
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_seconds) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      r.timed_out = true;
      return r;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return r;
}

std::string FindOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream ss(path);
  std::string d;
  while (std::getline(ss, d, ':')) {
    if (d.empty()) continue;
    const fs::path p = fs::path(d) / name;
    struct stat st{};
    if (::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

// Gives every id in a gnuplot SVG (gnuplot_canvas, gpPt0, textbox, …) and every reference to it
// (href="#…", url(#…)) the prefix, so several SVGs can live in one page. gnuplot itself repeats
// some ids within one SVG (gnuplot_plot_1 for a plot's key sample and its error bars): a repeat
// gets a "-2", "-3", … suffix, and references keep pointing at the first.

}  // namespace

std::string PrefixSvgIds(const std::string& svg, const std::string& prefix) {
  std::set<std::string> ids;
  for (size_t i = svg.find("id="); i != std::string::npos; i = svg.find("id=", i + 3)) {
    if (i == 0 || !std::isspace(static_cast<unsigned char>(svg[i - 1]))) continue;
    const size_t q = i + 3;
    if (q >= svg.size() || (svg[q] != '"' && svg[q] != '\'')) continue;
    const size_t e = svg.find(svg[q], q + 1);
    if (e == std::string::npos) break;
    ids.insert(svg.substr(q + 1, e - q - 1));
  }
  std::string out;
  out.reserve(svg.size() + 64 * ids.size());
  std::map<std::string, int> seen;
  size_t i = 0;
  while (i < svg.size()) {
    // id="X" / id='X'
    if (svg.compare(i, 3, "id=") == 0 && i > 0 && std::isspace(static_cast<unsigned char>(svg[i - 1])) &&
        i + 3 < svg.size() && (svg[i + 3] == '"' || svg[i + 3] == '\'')) {
      const size_t e = svg.find(svg[i + 3], i + 4);
      if (e == std::string::npos) {
        out += svg.substr(i);
        break;
      }
      const std::string id = svg.substr(i + 4, e - i - 4);
      const int n = ++seen[id];
      out += svg.substr(i, 4) + prefix + id + (n > 1 ? "-" + std::to_string(n) : "");
      i = e;
      continue;
    }
    // href="#X", url(#X)
    size_t ref = std::string::npos;
    if (svg.compare(i, 7, "href=\"#") == 0 || svg.compare(i, 7, "href='#") == 0) ref = i + 7;
    else if (svg.compare(i, 5, "url(#") == 0) ref = i + 5;
    if (ref != std::string::npos) {
      size_t e = ref;
      while (e < svg.size() && svg[e] != '"' && svg[e] != '\'' && svg[e] != ')') ++e;
      const std::string id = svg.substr(ref, e - ref);
      out += svg.substr(i, ref - i);
      if (ids.count(id)) out += prefix;
      out += id;
      i = e;
      continue;
    }
    out += svg[i++];
  }
  return out;
}

const char* Colour(size_t i) {
  static const char* kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                   "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return kColours[i % 10];
}

std::string LineStyle(size_t i, bool vary_points) {
  static const int kPoints[] = {7, 5, 9, 11, 13, 15};
  return std::string("lc rgb '") + Colour(i) + "' pt " + std::to_string(vary_points ? kPoints[i % 6] : 7) + " dt " +
         std::to_string(1 + (i / 10) % 5);
}

Gnuplot::Gnuplot() {
  exe_ = FindOnPath("gnuplot");
  if (exe_.empty()) {
    why_ = "gnuplot is not installed (not found on PATH; Debian: apt-get install gnuplot-nox)";
    return;
  }
  std::error_code ec;
  fs::path base = fs::temp_directory_path(ec);
  if (ec) base = "/tmp";
  std::string templ = (base / "mechbench-report-XXXXXX").string();
  if (!mkdtemp(templ.data())) {
    why_ = "cannot create a temporary folder for gnuplot in " + base.string() + ": " + std::strerror(errno);
    return;
  }
  tmp_ = templ;
  on_interrupt_ = std::make_shared<RemoveOnInterrupt>(tmp_.string(), true);
  const ProcResult r = RunProcess({exe_, "--version"}, tmp_ / "version.out", tmp_ / "version.err", 20);
  if (!r.started || r.timed_out || r.exit_code != 0) {
    why_ = exe_ + " --version failed" + (r.why.empty() ? "" : ": " + r.why);
    return;
  }
  version_ = Trim(ReadFile(tmp_ / "version.out"));
  available_ = true;
}

Gnuplot::~Gnuplot() {
  if (!tmp_.empty()) {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }
}

PlotResult Gnuplot::Plot(const std::string& name, const std::string& title, int width, int height,
                         const std::string& data, const std::string& body) {
  PlotResult res;
  if (!available_) {
    res.why = why_;
    return res;
  }
  const std::string stem = Slug(name) + "-" + std::to_string(++count_);
  const fs::path dat = tmp_ / (stem + ".dat"), gp = tmp_ / (stem + ".gp"), svg = tmp_ / (stem + ".svg"),
                 err = tmp_ / (stem + ".err");
  std::ostringstream script;
  script << "set encoding utf8\n"
         << "set terminal svg size " << width << "," << height << " dynamic enhanced font 'sans,10'\n"
         << "set output " << GpStr(svg.string()) << "\n"
         << "datafile = " << GpStr(dat.string()) << "\n"
         << body << "\nunset output\n";
  try {
    WriteFileOrThrow(dat, data);
    WriteFileOrThrow(gp, script.str());
  } catch (const std::exception& e) {
    res.why = e.what();
    return res;
  }
  const ProcResult r = RunProcess({exe_, "-d", gp.string()}, tmp_ / (stem + ".out"), err, 60);
  if (!r.started) {
    res.why = r.why;
    return res;
  }
  if (r.timed_out) {
    res.why = "gnuplot did not finish within 60 s";
    return res;
  }
  if (r.exit_code != 0) {
    std::string msg = Trim(ReadFile(err));
    if (msg.size() > 400) msg = msg.substr(0, 400) + " …";
    res.why = "gnuplot failed (exit " + std::to_string(r.exit_code) + ")" + (msg.empty() ? "" : ": " + msg);
    return res;
  }
  std::string text = ReadFile(svg);
  const size_t start = text.find("<svg");
  if (start == std::string::npos) {
    res.why = "gnuplot wrote no SVG";
    return res;
  }
  text = Trim(text.substr(start));
  // gnuplot titles every SVG "Gnuplot": give it the plot's title instead (shown on hover).
  if (auto t = text.find("<title>Gnuplot</title>"); t != std::string::npos)
    text.replace(t, std::strlen("<title>Gnuplot</title>"), "<title>" + Html(title) + "</title>");
  res.id_prefix = "p" + std::to_string(count_) + "-";
  res.svg = PrefixSvgIds(text, res.id_prefix);
  res.ok = true;
  return res;
}

}  // namespace mechbench::harness::report
