#include "mechbench/harness/process.h"

#include "mechbench/format.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <system_error>

namespace mechbench::harness {

namespace {

constexpr size_t kStderrKeep = 1024;  // the first and the last KB of what a child writes to stderr

void WriteAll(int fd, const std::string& s) {
  size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::write(fd, s.data() + off, s.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    off += static_cast<size_t>(n);
  }
}

// Reads what `fd` holds into `into`; true at its end. With `head`, only the first `keep` bytes go
// to `head` and the last `keep` stay in `into` (an engine's message comes first, a sanitizer's
// report or a crash's last words last).
bool ReadAvailable(int fd, std::string& into, size_t keep, std::string* head = nullptr, bool* cut = nullptr) {
  if (fd < 0) return true;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n > 0) {
      size_t from = 0;
      if (head && head->size() < keep) {
        from = std::min(keep - head->size(), static_cast<size_t>(n));
        head->append(buf, from);
      }
      into.append(buf + from, static_cast<size_t>(n) - from);
      if (keep && into.size() > 2 * keep) {
        into.erase(0, into.size() - keep);
        if (cut) *cut = true;
      }
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return false;
    return true;
  }
}

// What a child wrote to stderr, on one line: its first and last KB, what an engine said before it died.
std::string Said(const std::string& head, const std::string& tail, bool cut) {
  std::string s = head + (cut ? " … " : "") + (tail.size() > kStderrKeep && cut ? tail.substr(tail.size() - kStderrKeep) : tail);
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s;
}

}  // namespace

ChildProcess ChildProcess::Spawn(const std::function<std::string()>& fn) {
  return SpawnStreaming([&fn](const Send& send) { send(fn()); });
}

ChildProcess ChildProcess::SpawnStreaming(const std::function<void(const Send& send)>& fn) {
  const bool keep_output = std::getenv("MECHBENCH_CASE_OUTPUT") != nullptr;
  int out[2], err[2] = {-1, -1};
  if (::pipe(out) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  if (!keep_output && ::pipe(err) != 0) {
    ::close(out[0]), ::close(out[1]);
    throw std::system_error(errno, std::generic_category(), "pipe");
  }
  std::fflush(nullptr);
  [[maybe_unused]] const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    for (int fd : {out[0], out[1], err[0], err[1]})
      if (fd >= 0) ::close(fd);
    throw std::system_error(e, std::generic_category(), "fork");
  }
  if (pid == 0) {
#ifdef __linux__
    // A worker does not outlive the harness (an interrupted report leaves no process behind,
    // even one in the middle of a long batch).
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) std::_Exit(1);
#endif
    ::close(out[0]);
    if (!keep_output) {
      ::close(err[0]);
      const int null = ::open("/dev/null", O_WRONLY);
      if (null >= 0) ::dup2(null, 1);
      ::dup2(err[1], 2);
    }
    int code = 0;
    const int fd = out[1];
    try {
      fn([fd](const std::string& answer) {
        const uint64_t n = answer.size();
        WriteAll(fd, std::string(reinterpret_cast<const char*>(&n), sizeof n) + answer);
      });
    } catch (const std::exception& e) {
      std::fprintf(stderr, "exception: %s\n", e.what());
      code = 3;
    } catch (...) {
      std::fprintf(stderr, "exception of an unknown type\n");
      code = 3;
    }
    std::fflush(nullptr);
    ::close(out[1]);
    std::_Exit(code);
  }
  ::close(out[1]);
  if (err[1] >= 0) ::close(err[1]);
  ChildProcess c;
  c.pid_ = pid;
  c.out_fd_ = out[0];
  c.err_fd_ = err[0];
  c.start_ = std::chrono::steady_clock::now();
  ::fcntl(c.out_fd_, F_SETFL, O_NONBLOCK);
  if (c.err_fd_ >= 0) ::fcntl(c.err_fd_, F_SETFL, O_NONBLOCK);
  return c;
}

ChildProcess::ChildProcess(ChildProcess&& o) noexcept { *this = std::move(o); }

ChildProcess& ChildProcess::operator=(ChildProcess&& o) noexcept {
  if (this != &o) {
    std::swap(pid_, o.pid_);
    std::swap(out_fd_, o.out_fd_);
    std::swap(err_fd_, o.err_fd_);
    std::swap(out_, o.out_);
    std::swap(err_, o.err_);
    std::swap(err_head_, o.err_head_);
    std::swap(err_cut_, o.err_cut_);
    std::swap(start_, o.start_);
  }
  return *this;
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (out_fd_ >= 0) ::close(out_fd_);
  if (err_fd_ >= 0) ::close(err_fd_);
}

bool ChildProcess::Pump() {
  ReadAvailable(err_fd_, err_, kStderrKeep, &err_head_, &err_cut_);
  return ReadAvailable(out_fd_, out_, 0);
}

bool ChildProcess::NextAnswer(std::string& answer) {
  uint64_t n = 0;
  if (out_.size() < sizeof n) return false;
  std::memcpy(&n, out_.data(), sizeof n);
  if (out_.size() - sizeof n < n) return false;
  answer = out_.substr(sizeof n, n);
  out_.erase(0, sizeof n + n);
  err_.clear();
  err_head_.clear();
  err_cut_ = false;
  return true;
}

double ChildProcess::Elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

ChildOutcome ChildProcess::Finish(bool kill, double timeout) {
  if (kill) ::kill(pid_, SIGKILL);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  if (err_fd_ >= 0) {
    ::fcntl(err_fd_, F_SETFL, 0);  // the child is gone: read its stderr to the end
    ReadAvailable(err_fd_, err_, kStderrKeep, &err_head_, &err_cut_);
  }
  ChildOutcome o;
  o.wall = Elapsed();
  const std::string said = Said(err_head_, err_, err_cut_);
  const std::string tail = said.empty() ? "" : "; it wrote: " + said;
  if (kill) {
    o.kind = ChildOutcome::kTimedOut;
    o.detail = "killed after the time limit of " + Fmt(timeout) + " s" + tail;
  } else if (WIFSIGNALED(status)) {
    o.detail = "the process died of signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")" + tail;
  } else if (WIFEXITED(status) && WEXITSTATUS(status) == 3) {
    o.detail = said.empty() ? "exception" : said;
  } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    o.detail = "the process exited with code " + std::to_string(WEXITSTATUS(status)) + tail;
  } else {
    o.kind = ChildOutcome::kAnswered;
    // One answer (Spawn), or none left (a streaming child whose answers were taken).
    if (!out_.empty() && !(NextAnswer(o.payload) && out_.empty())) {
      o.kind = ChildOutcome::kCrashed;
      o.detail = "the process's answer is cut short" + tail;
    }
  }
  return o;
}

ChildOutcome RunInChild(const std::function<std::string()>& fn, double timeout) {
  ChildProcess c = ChildProcess::Spawn(fn);
  for (;;) {
    const double left = timeout - c.Elapsed();
    if (left <= 0) return c.Finish(true, timeout);
    pollfd fds[2] = {{c.fd(), POLLIN, 0}, {c.err_fd(), POLLIN, 0}};
    ::poll(fds, c.err_fd() >= 0 ? 2 : 1, static_cast<int>(std::min(left, 1.0) * 1000) + 1);
    if (c.Pump()) return c.Finish(false, timeout);
  }
}

}  // namespace mechbench::harness
