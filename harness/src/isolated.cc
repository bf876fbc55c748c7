#include "mechbench/harness/isolated.h"

#include "mechbench/harness/process.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace mechbench::harness {

namespace {

class Writer {
 public:
  void Int(int64_t v) { Raw(&v, sizeof v); }
  void Double(double v) { Raw(&v, sizeof v); }
  void Str(const std::string& s) {
    Int(static_cast<int64_t>(s.size()));
    out_.append(s);
  }
  void Vec(const Eigen::VectorXd& v) {
    Int(v.size());
    Raw(v.data(), sizeof(double) * static_cast<size_t>(v.size()));
  }
  std::string Take() { return std::move(out_); }

 private:
  void Raw(const void* p, size_t n) {
    if (n) out_.append(static_cast<const char*>(p), n);
  }
  std::string out_;
};

class MessageReader {
 public:
  explicit MessageReader(const std::string& in) : in_(in) {}
  int64_t Int() {
    int64_t v;
    Raw(&v, sizeof v);
    return v;
  }
  double Double() {
    double v;
    Raw(&v, sizeof v);
    return v;
  }
  size_t Count(size_t item_bytes) {
    const int64_t n = Int();
    if (n < 0 || static_cast<uint64_t>(n) > (in_.size() - pos_) / std::max<size_t>(item_bytes, 1))
      throw std::runtime_error("malformed result message (a count past its end)");
    return static_cast<size_t>(n);
  }
  std::string Str() {
    const size_t n = Count(1);
    std::string s = in_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  Eigen::VectorXd Vec() {
    const size_t n = Count(sizeof(double));
    Eigen::VectorXd v(static_cast<Eigen::Index>(n));
    Raw(v.data(), sizeof(double) * n);
    return v;
  }
  bool AtEnd() const { return pos_ == in_.size(); }

 private:
  void Raw(void* p, size_t n) {
    if (in_.size() - pos_ < n) throw std::runtime_error("truncated result message");
    if (n == 0) return;  // an empty vector's data() may be null
    std::memcpy(p, in_.data() + pos_, n);
    pos_ += n;
  }
  const std::string& in_;
  size_t pos_ = 0;
};

constexpr int64_t kMagic = 0x6d62726573756c74;  // "mbresult"

}  // namespace

std::string EncodeRun(const IsolatedRun& run) {
  const Result& r = run.result;
  Writer w;
  w.Int(kMagic);
  w.Str(r.method);
  w.Int(static_cast<int64_t>(r.status));
  w.Str(r.reason);
  w.Int(static_cast<int64_t>(r.messages.size()));
  for (const std::string& m : r.messages) w.Str(m);
  w.Int(static_cast<int64_t>(r.trajectory.size()));
  for (const Sample& s : r.trajectory) {
    w.Double(s.t);
    w.Double(s.residual);
    w.Vec(s.q);
    w.Vec(s.qd);
    w.Vec(s.qdd);
  }
  w.Int(static_cast<int64_t>(r.quantities.size()));
  for (const auto& [k, v] : r.quantities) {
    w.Str(k);
    w.Double(v);
  }
  for (double v : {r.cpu_seconds, r.cpu.setup, r.cpu.integration, r.cpu.observation, r.wall_seconds}) w.Double(v);
  w.Int(r.steps);
  w.Int(static_cast<int64_t>(r.settings.size()));
  for (const auto& [k, v] : r.settings) {
    w.Str(k);
    w.Str(v);
  }
  w.Double(run.startup.first);
  w.Double(run.startup.again);
  w.Double(run.startup.excess);
  w.Int(run.startup.runs);
  w.Int(run.startup.done);
  return w.Take();
}

IsolatedRun DecodeRun(const std::string& bytes) {
  MessageReader in(bytes);
  if (in.Int() != kMagic) throw std::runtime_error("not a result message");
  IsolatedRun run;
  Result& r = run.result;
  r.method = in.Str();
  const int64_t status = in.Int();
  if (status < 0 || status > static_cast<int64_t>(Status::kTimedOut)) throw std::runtime_error("malformed status");
  r.status = static_cast<Status>(status);
  r.reason = in.Str();
  for (size_t n = in.Count(8), k = 0; k < n; ++k) r.messages.push_back(in.Str());
  const size_t samples = in.Count(5 * 8);
  r.trajectory.resize(samples);
  for (Sample& s : r.trajectory) {
    s.t = in.Double();
    s.residual = in.Double();
    s.q = in.Vec();
    s.qd = in.Vec();
    s.qdd = in.Vec();
  }
  for (size_t n = in.Count(16), k = 0; k < n; ++k) {
    std::string key = in.Str();
    r.quantities[key] = in.Double();
  }
  r.cpu_seconds = in.Double();
  r.cpu.setup = in.Double();
  r.cpu.integration = in.Double();
  r.cpu.observation = in.Double();
  r.wall_seconds = in.Double();
  r.steps = in.Int();
  for (size_t n = in.Count(16), k = 0; k < n; ++k) {
    std::string key = in.Str();
    r.settings[key] = in.Str();
  }
  run.startup.first = in.Double();
  run.startup.again = in.Double();
  run.startup.excess = in.Double();
  run.startup.runs = static_cast<int>(in.Int());
  run.startup.done = in.Int() != 0;
  if (!in.AtEnd()) throw std::runtime_error("malformed result message (bytes after its end)");
  return run;
}

IsolatedRun RunMethodIsolated(const Method& method, const Model& model, const RunOptions& options, double timeout,
                              bool warm_up) {
  const double limit = timeout > 0 ? timeout : std::numeric_limits<double>::infinity();
  const ChildOutcome o = RunInChild(
      [&] {
        IsolatedRun run;
        if (warm_up) run.startup = WarmUp(method, model);
        run.result = method.Run(model, options);
        return EncodeRun(run);
      },
      limit);
  IsolatedRun run;
  run.result.method = method.name();
  if (o.kind == ChildOutcome::kAnswered) {
    try {
      return DecodeRun(o.payload);
    } catch (const std::exception& e) {
      run.result.status = Status::kCrashed;
      run.result.reason = std::string("its process sent an unreadable result: ") + e.what();
      return run;
    }
  }
  run.result.status = o.kind == ChildOutcome::kTimedOut ? Status::kTimedOut : Status::kCrashed;
  run.result.reason = o.detail;
  run.result.wall_seconds = o.wall;
  return run;
}

}  // namespace mechbench::harness
