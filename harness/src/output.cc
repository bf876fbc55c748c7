#include "mechbench/harness/output.h"

#include "mechbench/errors.h"
#include "mechbench/harness/report_render.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#ifdef __linux__
#include <sys/syscall.h>
#endif
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <system_error>

namespace mechbench::harness {

namespace fs = std::filesystem;

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos && (s.empty() || (s.front() != ' ' && s.back() != ' ')))
    return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

// ---- removal on interrupt -----------------------------------------------------------------------
namespace {

constexpr int kSlots = 16;  // AtomicFiles and report folders alive at once (run: --csv and --junit)
constexpr size_t kPathMax = 4096;
struct Slot {
  std::atomic<int> used{0};  // 0 free, 1 being filled, 2 armed
  pid_t owner = 0;           // a forked worker inherits the table: only the owner removes
  bool folder = false;
  char path[kPathMax] = {};
};
Slot g_slots[kSlots];
std::atomic<bool> g_installed{false};
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// The command that says it was interrupted (ReportInterrupts) and what it has written so far
// (SetInterruptNote): two buffers, the one in use switched atomically, so the handler never reads
// a note half-copied.
constexpr size_t kNoteMax = 1024;
pid_t g_reporter = 0;  // the process that prints the line (forked workers stay silent)
char g_command[64] = {};
char g_notes[2][kNoteMax] = {};
std::atomic<int> g_note{0};

size_t Length(const char* s) {
  size_t n = 0;
  while (s[n]) ++n;
  return n;
}

void Say(const char* s) {
  for (size_t n = Length(s); n > 0;) {
    const ssize_t w = ::write(2, s, n);
    if (w <= 0) return;
    s += w;
    n -= static_cast<size_t>(w);
  }
}

const char* SignalName(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGQUIT: return "SIGQUIT";
    default: return "a signal";
  }
}

// Only async-signal-safe calls: getpid, open, close, unlink, unlinkat, rmdir, the getdents64
// system call, sigaction, raise.
void EmptyFolder(const char* path) {
#ifdef __linux__
  const int fd = ::open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  alignas(8) char buf[4096];
  for (;;) {
    const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
    if (n <= 0) break;
    for (long off = 0; off < n;) {
      // struct linux_dirent64: u64 d_ino, s64 d_off, u16 d_reclen, u8 d_type, char d_name[]
      unsigned short reclen = 0;
      std::memcpy(&reclen, buf + off + 16, sizeof reclen);
      const char* name = buf + off + 19;
      if (std::strcmp(name, ".") != 0 && std::strcmp(name, "..") != 0) ::unlinkat(fd, name, 0);
      off += reclen;
    }
  }
  ::close(fd);
#else
  (void)path;
#endif
}

extern "C" void RemoveTemporariesAndDie(int sig) {
  const pid_t self = ::getpid();
  for (Slot& s : g_slots) {
    if (s.used.load() != 2 || s.owner != self) continue;
    if (s.folder) {
      EmptyFolder(s.path);
      ::rmdir(s.path);
    } else {
      ::unlink(s.path);
    }
  }
  if (g_reporter == self && g_command[0]) {
    Say("mechbench ");
    Say(g_command);
    Say(": interrupted (");
    Say(SignalName(sig));
    Say("); ");
    Say(g_notes[g_note.load()]);
    Say("\n");
    if (sig == SIGINT) ::_exit(130);  // 128 + SIGINT, as a shell reports a command stopped by Ctrl-C
  }
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  ::sigaction(sig, &dfl, nullptr);
  ::raise(sig);  // delivered on return from the handler: the process ends as the signal says
}

void InstallHandlers() {
  if (g_installed.exchange(true)) return;
  for (int sig : kSignals) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) continue;  // ignored or taken
    struct sigaction sa {};
    sa.sa_handler = RemoveTemporariesAndDie;
    sigemptyset(&sa.sa_mask);
    for (int other : kSignals) sigaddset(&sa.sa_mask, other);
    ::sigaction(sig, &sa, nullptr);
  }
}

}  // namespace

void ReportInterrupts(const std::string& command, const std::string& note) {
  std::snprintf(g_command, sizeof g_command, "%s", command.c_str());
  SetInterruptNote(note);
  g_reporter = ::getpid();
  InstallHandlers();
}

void SetInterruptNote(const std::string& note) {
  const int next = 1 - g_note.load();
  std::snprintf(g_notes[next], kNoteMax, "%s", note.c_str());
  g_note.store(next);
}

RemoveOnInterrupt::RemoveOnInterrupt(const std::string& path, bool folder) {
  if (path.size() >= kPathMax) return;  // not removed on an interrupt; never the case in practice
  InstallHandlers();
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!g_slots[i].used.compare_exchange_strong(expected, 1)) continue;
    Slot& s = g_slots[i];
    s.owner = ::getpid();
    s.folder = folder;
    std::memcpy(s.path, path.c_str(), path.size() + 1);
    s.used.store(2);
    slot_ = i;
    return;
  }
}

RemoveOnInterrupt::~RemoveOnInterrupt() {
  if (slot_ >= 0) g_slots[slot_].used.store(0);
}

// ---- AtomicFile ------------------------------------------------------------------------------
namespace {

// Where an output named `path` really goes: a symbolic link followed to its end (a relative link
// against its own folder), so that the file behind it is replaced and the link stays a link.
fs::path FinalTarget(const fs::path& path) {
  fs::path p = path;
  for (int hops = 0; hops < 40; ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    const fs::path t = fs::read_symlink(p, ec);
    if (ec) return p;
    p = t.is_absolute() ? t : p.parent_path() / t;
  }
  return p;
}

// The descriptor (1 or 2) when `path` (links followed) is what this process writes as its stdout
// or stderr (`--csv /dev/stdout`, to a terminal, a pipe or a redirected file), else -1: opening
// it anew would write over what is printed around it (a file) or interleave with it.
int OwnStream(const std::string& path) {
  struct stat target {};
  if (::stat(path.c_str(), &target) != 0) return -1;
  for (int fd : {1, 2}) {
    struct stat s {};
    if (::fstat(fd, &s) == 0 && s.st_dev == target.st_dev && s.st_ino == target.st_ino) return fd;
  }
  return -1;
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  std::error_code ec;
  const fs::file_status st = fs::status(path_, ec);  // links followed
  if (fs::is_directory(st))
    throw ScenarioError({path_, 0}, "is a folder, not a file", "name a file to write");
  own_fd_ = OwnStream(path_);
  if (own_fd_ >= 0) {  // held here and written to the descriptor whole by Commit(), after what was printed
    direct_ = true;
    stream_ = &held_;
    return;
  }
  if (fs::exists(st) && !fs::is_regular_file(st)) {
    // A device, a pipe or a socket (/dev/null): written through where it is, never replaced by a
    // new file (which, as root, turned /dev/null into one).
    direct_ = true;
    out_.open(path_, std::ios::binary | std::ios::out);
    if (!out_) throw ScenarioError({path_, 0}, "cannot write here", "check its permissions");
    return;
  }
  target_ = FinalTarget(path_).string();
  tmp_ = target_ + ".partial-" + std::to_string(::getpid());
  on_interrupt_ = std::make_unique<RemoveOnInterrupt>(tmp_, false);
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_)
    throw ScenarioError({path_, 0}, "cannot write here", "check that the folder exists and is writable");
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  if (!direct_) std::remove(tmp_.c_str());
}

void AtomicFile::Commit() {
  if (own_fd_ >= 0) {
    std::cout.flush();
    std::fflush(stdout);
    std::fflush(stderr);
    const std::string text = held_.str();
    const char* p = text.data();
    bool ok = true;
    for (size_t n = text.size(); n > 0 && ok;) {
      const ssize_t w = ::write(own_fd_, p, n);
      ok = w > 0;
      if (ok) {
        p += w;
        n -= static_cast<size_t>(w);
      }
    }
    if (!ok) throw ScenarioError({path_, 0}, "could not be written", "check where the output goes");
    committed_ = true;
    return;
  }
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (direct_) {
    if (!ok) throw ScenarioError({path_, 0}, "could not be written", "check the device or the pipe's reader");
    committed_ = true;
    return;
  }
  std::error_code ec;
  if (ok) fs::rename(tmp_, target_, ec);
  on_interrupt_.reset();  // renamed (or removed below): nothing of ours to remove any more
  if (!ok || ec) {
    std::remove(tmp_.c_str());
    throw ScenarioError({path_, 0}, "could not be written" + (ec ? ": " + ec.message() : std::string()),
                        "check the free space and the folder's permissions");
  }
  committed_ = true;
}

void RefuseToOverwriteInputs(const std::string& output, const std::vector<std::string>& inputs, const std::string& option) {
  std::error_code ec;
  if (!fs::exists(output, ec)) return;
  for (const std::string& in : inputs) {
    std::error_code e1;
    if (fs::exists(in, e1) && fs::equivalent(output, in, e1))
      throw ScenarioError({output, 0}, option + " names an input of this command (" + in + ")",
                          "write the output to another file");
  }
}

void RefuseClashingOutputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  const auto where = [](const std::string& p) {
    std::error_code ec;
    const fs::path a = fs::absolute(FinalTarget(p), ec).lexically_normal();
    const fs::path w = fs::weakly_canonical(a, ec);
    return ec ? a : w;
  };
  for (size_t i = 0; i < outputs.size(); ++i)
    for (size_t j = i + 1; j < outputs.size(); ++j) {
      if (outputs[i].second.empty() || outputs[j].second.empty()) continue;
      std::error_code ec;
      const bool same = where(outputs[i].second) == where(outputs[j].second) ||
                        (fs::exists(outputs[i].second, ec) && fs::equivalent(outputs[i].second, outputs[j].second, ec));
      if (same && !IsStream(outputs[i].second))
        throw ScenarioError({outputs[j].second, 0}, outputs[i].first + " and " + outputs[j].first + " name the same file",
                            "give each output its own file");
    }
}

bool IsStream(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  return fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st);
}

void CreateOutputFolder(const std::string& dir) {
  std::error_code ec;
  const fs::path out(dir.empty() ? std::string(".") : dir);
  if (fs::exists(out, ec) && !fs::is_directory(out, ec))
    throw ScenarioError({dir, 0}, "is a file, not a folder", "name a folder for the output (it is created if needed)");
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out))
    throw ScenarioError({dir, 0}, "cannot create the folder" + (ec ? ": " + ec.message() : std::string()),
                        "check the path and its permissions");
  if (::access(out.c_str(), W_OK) != 0)
    throw ScenarioError({dir, 0}, "cannot write into the folder", "check its permissions");
}

ReportWriter::ReportWriter(std::string dir) : dir_(dir.empty() ? std::string(".") : std::move(dir)) {
  CreateOutputFolder(dir_);
  const std::string lock = (fs::path(dir_) / ".mechbench-report.lock").string();
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0) throw ScenarioError({dir_, 0}, "cannot create its lock file", "check the folder's permissions");
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw ScenarioError({dir_, 0}, "another mechbench report is writing into this folder",
                        "wait for it, or give this one another --out");
  }
}

ReportWriter::~ReportWriter() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock; the lock file stays (harmless, reused)
}

ReportWriter::Info ReportWriter::Write(const nlohmann::json& results) {
  const fs::path tmp = fs::path(dir_) / (".partial-" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(tmp, ec);
  RemoveOnInterrupt on_interrupt(tmp.string(), true);
  RenderInfo rendered;
  try {
    rendered = WriteReportFiles(results, tmp.string());
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    throw ScenarioError({dir_, 0}, std::string("the report could not be written: ") + e.what(),
                        "check the free space and the folder's permissions");
  }
  // Every file in place, or none: the interrupts that would stop us half-way are held meanwhile.
  sigset_t hold, before;
  sigemptyset(&hold);
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaddset(&hold, sig);
  ::sigprocmask(SIG_BLOCK, &hold, &before);
  std::string failed;
  for (const auto& entry : fs::directory_iterator(tmp, ec)) {
    std::error_code e2;
    fs::rename(entry.path(), fs::path(dir_) / entry.path().filename(), e2);
    if (e2) failed = entry.path().filename().string() + ": " + e2.message();
  }
  // Still held: an interrupt waiting now is told the report is in place.
  if (failed.empty()) SetInterruptNote("the report was written whole to " + dir_);
  ::sigprocmask(SIG_SETMASK, &before, nullptr);
  fs::remove_all(tmp, ec);
  if (!failed.empty()) throw ScenarioError({dir_, 0}, "could not move the report into place (" + failed + ")");
  return {rendered.gnuplot, rendered.plots};
}

}  // namespace mechbench::harness
