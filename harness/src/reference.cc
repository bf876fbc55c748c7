#include "mechbench/harness/reference.h"

#include "mechbench/harness/output.h"

#include "mechbench/numeric/reference.h"
#include "mechbench/references/registry.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace mechbench::harness {
namespace {

namespace fs = std::filesystem;

// Bump when the reference's formulation or settings change: old cache entries then miss.
constexpr const char* kReferenceVersion = "mechbench-reference v8 (a scene without constraints: its partitioning run named the same ODE, not a confirmation; exact references named by the scene from the registry: the N-four-bar, the pendulum in Jacobi's functions confirmed over its first 200 s; agreement of q, q̇, q̈; Baumgarte+DOPRI5 1e-12, confirmed by CP+DOPRI5 (at 1e-12, else 1e-10) or ALI3-P 1e-4 to 1e-8 per second of motion, measured by CompareMotion; the N-four-bar: its exact one-DOF motion, confirmed piecewise and over the whole run in complex time)";

struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void Add(const std::string& s) {
    for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
    h = (h ^ 0xff) * 1099511628211ull;  // separator, so "ab"+"c" differs from "a"+"bc"
  }
  void Add(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    Add(std::string(buf));
  }
};

// The model's content as numbers and names: a scenario loaded from text (no file) still gets a key.
void AddModel(Fnv& f, const Model& m) {
  f.Add(m.length_unit);
  for (const Point& p : m.points) f.Add(p.name), f.Add(p.fixed ? 1.0 : 0.0), f.Add(p.p_W.x()), f.Add(p.p_W.y());
  for (const Body& b : m.bodies) {
    f.Add(b.name);
    for (int p : b.points) f.Add(static_cast<double>(p));
    for (const auto& v : b.p_B) f.Add(v.x()), f.Add(v.y());
    f.Add(b.mass), f.Add(b.com_B.x()), f.Add(b.com_B.y()), f.Add(b.inertia_com);
  }
  for (const Joint& j : m.joints)
    f.Add(static_cast<double>(j.type)), f.Add(static_cast<double>(j.point)), f.Add(static_cast<double>(j.line[0])),
        f.Add(static_cast<double>(j.line[1])), f.Add(static_cast<double>(j.body)), f.Add(j.eliminate ? 1.0 : 0.0);
  for (const Coordinate& c : m.coordinates)
    f.Add(c.name), f.Add(static_cast<double>(c.type)), f.Add(static_cast<double>(c.form)), f.Add(c.guess),
        f.Add(static_cast<double>(c.vec[0])), f.Add(static_cast<double>(c.vec[1])), f.Add(static_cast<double>(c.ref[0])),
        f.Add(static_cast<double>(c.ref[1]));
  for (const Driver& d : m.initial) f.Add(d.coordinate), f.Add(d.value), f.Add(d.velocity);
  f.Add(m.gravity.x()), f.Add(m.gravity.y());
  for (const PointForce& p : m.forces) {
    f.Add(static_cast<double>(p.point)), f.Add(p.f_W.x()), f.Add(p.f_W.y());
    if (p.IsConstantWorld()) continue;  // (only then: the keys of other scenes stay as they were)
    f.Add("varying"), f.Add(static_cast<double>(p.frame)), f.Add(p.components.x()), f.Add(p.components.y());
    for (const auto& law : p.law) f.Add(law ? "law " + law->text() : std::string("constant"));
  }
  f.Add("springs");
  for (const SpringDamper& s : m.springs) {
    f.Add(static_cast<double>(s.points[0])), f.Add(static_cast<double>(s.points[1])), f.Add(s.stiffness),
        f.Add(s.damping), f.Add(s.free_length), f.Add(s.preload);
    if (!s.HasLaw()) continue;  // (only then: the keys of other scenes stay as they were)
    for (const auto& law : s.law) f.Add(law ? "law " + law->text() : std::string("constant"));
  }
  f.Add("torques");
  for (const BodyTorque& t : m.torques) {
    f.Add(static_cast<double>(t.body)), f.Add(t.torque);
    if (t.law) f.Add("law " + t.law->text());  // (only then: the keys of other scenes stay as they were)
  }
  if (!m.torsions.empty()) f.Add("torsions");
  for (const TorsionSpring& s : m.torsions)
    f.Add(static_cast<double>(s.slot)), f.Add(s.stiffness), f.Add(s.damping), f.Add(s.free_angle), f.Add(s.preload);
  f.Add(m.analysis.t0), f.Add(m.analysis.t1), f.Add(static_cast<double>(m.analysis.samples));
  f.Add("exact");
  if (m.exact_reference) f.Add(m.exact_reference->name);
}

bool Write(const std::string& path, const std::string& key, const ReferenceRecord& r) {
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());  // two processes never share one
  const RemoveOnInterrupt on_interrupt(tmp, false);  // an interrupt leaves no stray temporary in the cache
  {
    std::ofstream out(tmp);
    if (!out) return false;
    out.precision(17);
    out << kReferenceVersion << "\nkey " << key << "\ndescription " << r.description << "\n"
        << "agreement " << r.agreement << " qd " << (r.agreement_qd >= 0 ? r.agreement_qd : -1.0) << " qdd "
        << (r.agreement_qdd >= 0 ? r.agreement_qdd : -1.0) << " tolerance " << r.tolerance << " confirmed " << r.confirmed << "\n"
        << "samples " << r.trajectory.size() << " n " << (r.trajectory.empty() ? 0 : r.trajectory[0].q.size()) << "\n";
    for (const Sample& s : r.trajectory) {
      out << s.t;
      for (const Eigen::VectorXd* v : {&s.q, &s.qd, &s.qdd})
        for (Eigen::Index i = 0; i < v->size(); ++i) out << ' ' << (*v)[i];
      out << '\n';
    }
    if (!out) return false;
  }
  fs::rename(tmp, path, ec);  // whole files only, even with two runs at once
  return !ec;
}

// An entry that is absent or of another version or key is a miss; one that is there but does not
// read as this model's trajectory (truncated, edited, a sample count no run of it has) is corrupt.
enum class CacheRead { kMiss, kHit, kCorrupt };

CacheRead Read(const std::string& path, const std::string& key, const Model& model, ReferenceRecord& r, std::string& why) {
  std::ifstream in(path);
  if (!in) return CacheRead::kMiss;
  std::string line, word;
  if (!std::getline(in, line) || line != kReferenceVersion) return CacheRead::kMiss;
  if (!std::getline(in, line) || line != "key " + key) return CacheRead::kMiss;
  if (!std::getline(in, line) || line.rfind("description ", 0) != 0) {
    why = "no description line";
    return CacheRead::kCorrupt;
  }
  r.description = line.substr(12);
  long long samples = 0, n = 0;
  in >> word >> r.agreement >> word >> r.agreement_qd >> word >> r.agreement_qdd >> word >> r.tolerance >> word >>
      r.confirmed >> word >> samples >> word >> n;
  if (r.agreement_qd < 0) r.agreement_qd = kNaN;  // written as −1: not measured
  if (r.agreement_qdd < 0) r.agreement_qdd = kNaN;
  // The model says what the trajectory must hold: its samples of its coordinates.
  const long long want_samples = model.analysis.HasMotion() ? model.analysis.samples : 1;
  const long long want_n = static_cast<long long>(model.q_layout.size());
  if (!in || samples != want_samples || n != want_n) {
    why = "its header says " + std::to_string(samples) + " samples of " + std::to_string(n) + " coordinates, the scene has " +
          std::to_string(want_samples) + " of " + std::to_string(want_n);
    return CacheRead::kCorrupt;
  }
  r.trajectory.resize(static_cast<size_t>(samples));
  for (Sample& s : r.trajectory) {
    s.q.resize(n), s.qd.resize(n), s.qdd.resize(n);
    in >> s.t;
    for (Eigen::VectorXd* v : {&s.q, &s.qd, &s.qdd})
      for (long long i = 0; i < n; ++i) in >> (*v)[i];
  }
  if (!in) {
    why = "its samples end early or hold something that is not a number";
    return CacheRead::kCorrupt;
  }
  return CacheRead::kHit;
}

}  // namespace

std::string ReferenceCacheDir() {
  if (const char* env = std::getenv("MECHBENCH_REFERENCE_CACHE")) {
    const std::string v = env;
    return (v.empty() || v == "off" || v == "0") ? std::string() : v;
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/mechbench";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/mechbench";
  return {};
}

std::string ReferenceKey(const Model& model) {
  Fnv f;
  f.Add(kReferenceVersion);
  std::ifstream in(model.source_file, std::ios::binary);
  if (in) {
    std::ostringstream text;
    text << in.rdbuf();
    f.Add(text.str());
  }
  AddModel(f, model);
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(f.h));
  return buf;
}

ReferenceRecord GetReference(const Model& model, double cpu_budget) {
  ReferenceRecord r;
  const std::string dir = ReferenceCacheDir();
  const std::string key = ReferenceKey(model);
  const std::string path = dir.empty() ? std::string() : dir + "/" + model.name + "-" + key + ".ref";
  std::string why;
  const CacheRead got = path.empty() ? CacheRead::kMiss : Read(path, key, model, r, why);
  if (got == CacheRead::kHit) {
    r.from_cache = true;
    r.cache_file = path;
    return r;
  }
  if (got == CacheRead::kCorrupt) {
    std::fprintf(stderr, "warning: discarded the corrupt reference cache entry %s (%s); computing it again\n", path.c_str(),
                 why.c_str());
    std::error_code ec;
    fs::remove(path, ec);
  }
  r = ReferenceRecord{};
  numeric::ReferenceOptions options;
  options.cpu_budget = cpu_budget;
  const numeric::Reference ref = references::ReferenceFor(model, options);
  r.description = ref.description;
  r.agreement = ref.agreement;
  r.agreement_qd = ref.agreement_qd;
  r.agreement_qdd = ref.agreement_qdd;
  r.tolerance = ref.tolerance;
  r.confirmed = ref.confirmed;
  r.cpu_seconds = ref.primary.cpu_seconds + ref.confirmation.cpu_seconds;
  if (ref.primary.ok()) r.trajectory = ref.primary.trajectory;
  // Only a confirmed reference is worth keeping; a failed one is recomputed (and reported) next time.
  if (!path.empty() && r.confirmed && Write(path, key, r)) r.cache_file = path;
  return r;
}

}  // namespace mechbench::harness
