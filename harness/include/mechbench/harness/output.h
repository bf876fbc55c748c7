// Output files written safely: nothing is touched until the work that fills them has succeeded.
//
// AtomicFile writes into a temporary file beside its target and renames it into place on
// Commit(); a command that fails (bad input, an exception, an interrupt) leaves the target as it
// was and removes the temporary file. An output path that names one of the command's inputs is
// refused before any work starts. Problems with an output path are bad input (ScenarioError,
// exit code 2) naming the path.
#pragma once

#include <nlohmann/json.hpp>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace mechbench::harness {

// One CSV field as RFC 4180 quotes it: in double quotes (doubled inside) when it holds a comma, a
// quote, a line break, or leading or trailing spaces.
std::string CsvField(const std::string& s);

// A temporary path removed when SIGINT, SIGTERM, SIGHUP or SIGQUIT ends the process (an
// interrupted command runs no destructors): the handler, async-signal-safe, unlinks every path
// still registered by this process (a folder: its files, then itself), then re-raises the signal
// with its default action, so the exit status still says how the command ended. A signal the
// process ignores (nohup) stays ignored. AtomicFile and ReportWriter register their temporaries.
class RemoveOnInterrupt {
 public:
  RemoveOnInterrupt(const std::string& path, bool folder);
  ~RemoveOnInterrupt();  // no longer removed: renamed into place, or removed by its owner
  RemoveOnInterrupt(const RemoveOnInterrupt&) = delete;
  RemoveOnInterrupt& operator=(const RemoveOnInterrupt&) = delete;

 private:
  int slot_ = -1;
};

// Makes an interrupt (SIGINT, SIGTERM, SIGHUP, SIGQUIT) of this process end `command` with one
// line on stderr, "mechbench COMMAND: interrupted (SIGINT); NOTE", after the temporaries above
// are removed; SIGINT then exits with 130 (128 + 2, what a shell shows for Ctrl-C), the others
// end the process as their default action does. Forked workers stay silent. NOTE says what was
// and was not written; SetInterruptNote updates it as outputs are committed.
void ReportInterrupts(const std::string& command, const std::string& note);
void SetInterruptNote(const std::string& note);

// An output file written whole or not at all: into a temporary file beside its target, renamed
// onto it by Commit(). A link is followed (the file behind it is replaced, the link stays); a
// device, a pipe or a socket (/dev/null, /dev/stdout in a pipeline) and the file this process's
// stdout or stderr goes to are written through, never replaced.
class AtomicFile {
 public:
  // Opens the temporary file now, so that an unwritable folder is reported before the work.
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  std::ostream& stream() { return *stream_; }
  // Flushes, checks every write succeeded and renames the temporary file to the target.
  void Commit();
  const std::string& path() const { return path_; }

 private:
  std::string path_, target_, tmp_;  // target_: path_ with its links followed (the file replaced)
  std::unique_ptr<RemoveOnInterrupt> on_interrupt_;
  std::ofstream out_;
  std::ostringstream held_;       // for our own stdout or stderr
  std::ostream* stream_ = &out_;  // out_, or held_
  int own_fd_ = -1;               // 1 or 2 when path_ is where this process's stdout or stderr goes
  bool committed_ = false;
  bool direct_ = false;  // a device, a pipe or our own stdout's file: written through, not replaced
};

// Throws ScenarioError (bad input) when two of a command's outputs, as (option, path) pairs, name
// one file (links followed; a device such as /dev/null may take several).
void RefuseClashingOutputs(const std::vector<std::pair<std::string, std::string>>& outputs);
// Whether `path` (links followed) is a device, a pipe or a socket: written through, never replaced.
bool IsStream(const std::string& path);

// Creates the folder `dir` (and its parents) for outputs, or throws ScenarioError naming it: a file
// in the way, no permission.
void CreateOutputFolder(const std::string& dir);

// The report's files (report_render.h) into DIR all at once. The constructor, before any work,
// creates DIR and takes an exclusive lock on DIR/.mechbench-report.lock for the object's life:
// a second report into the same folder stops at once (exit 2) instead of mixing its files in.
// Write() renders into a temporary folder inside DIR, then moves each file into place with
// SIGINT, SIGTERM, SIGHUP and SIGQUIT held, so an interrupt leaves the old files or the new ones,
// never a mixture; a file of the user's in DIR is never touched. An interrupt while it renders
// removes the temporary folder (RemoveOnInterrupt).
class ReportWriter {
 public:
  explicit ReportWriter(std::string dir);
  ~ReportWriter();
  ReportWriter(const ReportWriter&) = delete;
  ReportWriter& operator=(const ReportWriter&) = delete;
  struct Info {
    bool gnuplot = false;
    int plots = 0;
  };
  Info Write(const nlohmann::json& results);
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  int lock_fd_ = -1;
};

// Throws ScenarioError when `output` is the same file as one of `inputs` (after resolving links
// and relative paths), or an existing folder where a file is wanted.
void RefuseToOverwriteInputs(const std::string& output, const std::vector<std::string>& inputs, const std::string& option);

}  // namespace mechbench::harness
