// Worker processes: a function run in a forked child, its answer back through a pipe, with a time
// limit. A child that dies (an engine's abort or segfault), throws or overruns is told apart from
// one that answered, with the last lines it wrote to stderr (an engine's own message, e.g.
// "ODE INTERNAL ERROR 1: assertion "dMassCheck(mass)" failed") in the detail. Used by `run` and
// `check` for each method, and by the campaign for each case.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <functional>
#include <string>

namespace mechbench::harness {

struct ChildOutcome {
  enum Kind { kAnswered, kCrashed, kTimedOut };
  Kind kind = kCrashed;
  std::string payload;  // kAnswered: what the function returned
  std::string detail;   // otherwise: why there is no answer, in words
  double wall = 0;      // [s] from fork to reaping
};

class ChildProcess {
 public:
  // Forks; the child runs `fn`, writes its bytes to a pipe and exits with _Exit (no static
  // destructors of the parent's libraries). Its stdout goes to /dev/null; its stderr is kept (the
  // first and the last KB) unless MECHBENCH_CASE_OUTPUT is set, when both stay on the terminal. A function
  // that throws leaves the child with exit code 3 and its message on stderr.
  static ChildProcess Spawn(const std::function<std::string()>& fn);
  // The same for a child that answers several times (a batch of cases, each answer sent when it
  // is ready): `fn` is given `send`, which writes one length-prefixed answer to the pipe; the
  // parent takes them in order with NextAnswer.
  using Send = std::function<void(const std::string&)>;
  static ChildProcess SpawnStreaming(const std::function<void(const Send& send)>& fn);
  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess();  // kills and reaps a child still running

  int fd() const { return out_fd_; }  // readable when the answer or its end is there (poll)
  int err_fd() const { return err_fd_; }
  // Reads what both pipes hold without blocking; true once the answer pipe is at its end.
  bool Pump();
  double Elapsed() const;
  // A streaming child's next whole answer, taken out of what Pump has read; false while none is
  // complete. After one, the stderr kept so far is dropped, so that a later failure's detail is
  // what the child wrote since (Pump reads stderr first: what the child wrote before the answer
  // is in by then).
  bool NextAnswer(std::string& answer);
  // Reaps the child (after Pump() returned true, or to give up on it: `kill` first sends SIGKILL).
  ChildOutcome Finish(bool kill, double timeout_seconds);

 private:
  ChildProcess() = default;
  pid_t pid_ = -1;
  int out_fd_ = -1, err_fd_ = -1;
  std::string out_, err_, err_head_;  // the answer; stderr's last and first KB
  bool err_cut_ = false;               // stderr was longer than both together
  std::chrono::steady_clock::time_point start_;
};

// Runs `fn` in a child and waits for its answer, at most `timeout_seconds`.
ChildOutcome RunInChild(const std::function<std::string()>& fn, double timeout_seconds);

}  // namespace mechbench::harness
