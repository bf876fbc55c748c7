#include "mechbench/harness/output.h"

#include "mechbench/errors.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
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

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  std::error_code ec;
  if (fs::is_directory(path_, ec))
    throw ScenarioError({path_, 0}, "is a folder, not a file", "name a file to write");
  tmp_ = path_ + ".partial-" + std::to_string(::getpid());
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_)
    throw ScenarioError({path_, 0}, "cannot write here", "check that the folder exists and is writable");
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::remove(tmp_.c_str());
}

void AtomicFile::Commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  std::error_code ec;
  if (ok) fs::rename(tmp_, path_, ec);
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

}  // namespace mechbench::harness
