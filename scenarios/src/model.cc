#include "mechbench/model.h"

#include "mechbench/errors.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mechbench {

void AssertionFailed(const char* expr, const char* file, int line, const char* msg) {
  std::fprintf(stderr, "mechbench internal error: %s:%d: %s (%s)\n", file, line, msg, expr);
  std::abort();
}

namespace {
template <class V>
int IndexByName(const V& v, const std::string& n) {
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i].name == n) return static_cast<int>(i);
  return -1;
}
}  // namespace

int Model::PointIndex(const std::string& n) const { return IndexByName(points, n); }
int SpatialModel::EntityIndex(const std::string& n) const { return IndexByName(entities, n); }
int Model::BodyIndex(const std::string& n) const { return IndexByName(bodies, n); }
int Model::SlotIndex(const std::string& n) const { return IndexByName(q_layout, n); }

int Model::SlotOf(int point, int axis) const {
  for (size_t i = 0; i < q_layout.size(); ++i)
    if (q_layout[i].point == point && q_layout[i].axis == axis) return static_cast<int>(i);
  return -1;
}

Model Model::InitialAsDrivers() const {
  Model d = *this;
  d.drivers = initial;
  for (Driver& drv : d.drivers) drv.acceleration = 0.0;
  d.initial.clear();
  return d;
}

bool Model::HasMass() const {
  for (const Body& b : bodies)
    if (b.HasMass()) return true;
  for (const SpatialBody& b : spatial.bodies)
    if (b.HasMass()) return true;
  return false;
}

double Model::LengthScale() const {
  double L = 0.0;
  for (const Point& p : points)
    if (p.p_W.allFinite()) L = std::max(L, p.p_W.norm());
  for (const Body& b : bodies)
    for (const Eigen::Vector2d& v : b.p_B)
      if (v.allFinite()) L = std::max(L, v.norm());
  for (const SpatialEntity& e : spatial.entities)
    if (!e.vector && e.r_W.allFinite()) L = std::max(L, e.r_W.norm());
  return L > 0 ? L : 1.0;
}

namespace {
// Signed angle from vector a to vector b in (-π, π].
double SignedAngle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
}
}  // namespace

Eigen::VectorXd Model::GuessQ() const {
  Eigen::VectorXd q(q_layout.size());
  for (size_t i = 0; i < q_layout.size(); ++i) {
    const Slot& s = q_layout[i];
    if (s.point >= 0) {
      q[i] = points[s.point].p_W[s.axis];
      continue;
    }
    if (s.entity >= 0) {  // a spatial scene: its file pose
      q[i] = spatial.entities[s.entity].r_W[s.axis];
      continue;
    }
    if (s.spatial_coordinate >= 0) {
      q[i] = spatial.coordinates[s.spatial_coordinate].value;
      continue;
    }
    const Coordinate& c = coordinates[s.coordinate];
    if (c.guess == c.guess) {
      q[i] = c.guess;
    } else if (c.type == CoordinateType::kAngle) {
      const Eigen::Vector2d v = points[c.vec[1]].p_W - points[c.vec[0]].p_W;
      const Eigen::Vector2d r = c.ref[0] < 0 ? Eigen::Vector2d(1, 0)
                                             : Eigen::Vector2d(points[c.ref[1]].p_W - points[c.ref[0]].p_W);
      q[i] = SignedAngle(r, v);
      // The dot form only knows |θ| (cos is even): start from the positive branch.
      if (c.form == AngleForm::kDot) q[i] = std::fabs(q[i]);
    } else if (c.type == CoordinateType::kDistance) {
      q[i] = (points[c.vec[1]].p_W - points[c.vec[0]].p_W).norm();
    } else {
      q[i] = 0.0;  // a gear member's rotation: any phase will do
    }
  }
  return q;
}

}  // namespace mechbench

namespace mechbench {

Jet2 Driver::JetAt(double t, double t0) const {
  if (law) {
    const Jet2 x[1] = {{t, 1, 0}};
    return law->Eval(x);
  }
  const double s = t - t0;
  return {value + velocity * s + 0.5 * acceleration * s * s, velocity + acceleration * s, acceleration};
}
double Driver::At(double t, double t0) const {
  if (law) return law->Eval(&t);
  const double s = t - t0;
  return value + velocity * s + 0.5 * acceleration * s * s;
}
double Driver::RateAt(double t, double t0) const { return law ? JetAt(t, t0).d : velocity + acceleration * (t - t0); }
double Driver::AccelerationAt(double t, double t0) const { return law ? JetAt(t, t0).dd : acceleration; }
bool Driver::SameMotion(const Driver& o) const {
  if (law || o.law) return law && o.law && law->text() == o.law->text();
  return value == o.value && velocity == o.velocity && acceleration == o.acceleration;
}

}  // namespace mechbench

namespace mechbench {
bool Model::HasLoadLaws() const {
  for (const BodyTorque& t : torques)
    if (t.law) return true;
  for (const SpatialLoad& l : spatial.torques)
    if (l.HasLaw()) return true;
  for (const SpatialLoad& f : spatial.forces)
    if (f.HasLaw()) return true;
  for (const PointForce& f : forces)
    if (f.HasLaw()) return true;
  return HasSpringLaws();
}
bool Model::HasSpringLaws() const {
  for (const SpringDamper& s : springs)
    if (s.HasLaw()) return true;
  for (const SpringDamper& s : spatial.springs)
    if (s.HasLaw()) return true;
  return false;
}
bool Model::HasVaryingPointForces() const {
  for (const PointForce& f : forces)
    if (!f.IsConstantWorld()) return true;
  return spatial.HasVaryingForces();
}
bool SpatialModel::HasVaryingForces() const {
  for (const SpatialLoad& f : forces)
    if (f.IsVarying()) return true;
  return false;
}
}  // namespace mechbench
