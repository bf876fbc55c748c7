#include "mechbench/numeric/natural_model.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/spatial.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace mechbench::numeric {

const char* ToString(RowKind kind) {
  switch (kind) {
    case RowKind::kBodyDistance: return "distance";
    case RowKind::kBodyLinearX: return "linear x";
    case RowKind::kBodyLinearY: return "linear y";
    case RowKind::kPointOnLine: return "collinearity";
    case RowKind::kGear: return "gear mesh";
    case RowKind::kAngleCos: return "cos";
    case RowKind::kAngleSin: return "sin";
    case RowKind::kAngleDot: return "dot";
    case RowKind::kAngleCross: return "cross";
    case RowKind::kDistance: return "distance coordinate";
    case RowKind::kCoupling: return "coupling";
    case RowKind::kUnit3: return "unit vector";
    case RowKind::kDistance3: return "distance 3-D";
    case RowKind::kDot3: return "dot product";
    case RowKind::kLinear3: return "linear combination";
    case RowKind::kPointOnLine3: return "point on line 3-D";
    case RowKind::kAngle3: return "angle about an axis";
  }
  return "?";
}

std::string ConstraintRow::Where() const { return element + " (" + src.Str() + ")"; }

namespace {

double MetersPerUnit(const std::string& unit) {
  if (unit == "mm") return 1e-3;
  if (unit == "cm") return 1e-2;
  return 1.0;
}

class Compiler {
 public:
  explicit Compiler(const Model& model) : m_(model) {}

  NaturalModel Run() {
    out_.model = m_;
    out_.n = static_cast<int>(m_.q_layout.size());
    out_.meters_per_unit = MetersPerUnit(m_.length_unit);
    Layout();
    Scales();
    for (size_t b = 0; b < m_.bodies.size(); ++b) BodyRows(static_cast<int>(b));
    for (const Joint& j : m_.joints) JointRows(j);
    for (size_t c = 0; c < m_.coordinates.size(); ++c) CoordinateRows(static_cast<int>(c));
    for (const Coupling& c : m_.couplings) CouplingRow(c);
    Drivers();
    return std::move(out_);
  }

 private:
  void Layout() {
    const size_t P = m_.points.size();
    out_.point_slot.assign(P, {-1, -1});
    out_.point_const.resize(P);
    for (size_t p = 0; p < P; ++p) out_.point_const[p] = m_.points[p].p_W;
    out_.coordinate_slot.assign(m_.coordinates.size(), -1);
    out_.member_slot.assign(m_.bodies.size(), -1);
    for (int s = 0; s < out_.n; ++s) {
      const Model::Slot& slot = m_.q_layout[s];
      if (slot.point >= 0) {
        MB_ASSERT(slot.axis == 0 || slot.axis == 1, "point slot without an axis");
        out_.point_slot[slot.point][slot.axis] = s;
      } else {
        MB_ASSERT(slot.coordinate >= 0, "slot is neither a point nor a coordinate");
        out_.coordinate_slot[slot.coordinate] = s;
        const Coordinate& c = m_.coordinates[slot.coordinate];
        if (c.type == CoordinateType::kRotation && c.body >= 0) out_.member_slot[c.body] = s;
      }
    }
    for (size_t p = 0; p < P; ++p)
      for (int axis = 0; axis < 2; ++axis)
        if (out_.point_slot[p][axis] < 0 && !std::isfinite(out_.point_const[p][axis]))
          throw ScenarioError(m_.points[p].src, "point " + m_.points[p].name + " has no position",
                              "give it fixed: [x, y] or at: [x, y]");
  }

  void Scales() {
    out_.length_scale = m_.LengthScale();
    out_.q_scale = Eigen::VectorXd::Ones(out_.n);
    for (int s = 0; s < out_.n; ++s) {
      const Model::Slot& slot = m_.q_layout[s];
      const bool is_length = slot.point >= 0 ||
                             m_.coordinates[slot.coordinate].type == CoordinateType::kDistance;
      if (is_length) out_.q_scale[s] = out_.length_scale;
    }
  }

  bool Moves(int p) const { return out_.point_slot[p][0] >= 0 || out_.point_slot[p][1] >= 0; }

  void BodyRows(int bi) {
    const Body& body = m_.bodies[bi];
    if (body.points.size() < 2) return;  // gear-train members: rows come from their meshes
    const std::string what = "body " + body.name;
    MB_ASSERT(body.p_B.size() == body.points.size(), "body without body-frame coordinates");
    const double L = body.Length();
    if (!(L > 0))
      throw ScenarioError(body.src, what + ": its first two points are at zero distance",
                          "give it a positive length");
    const int p0 = body.points[0], p1 = body.points[1];
    if (!Moves(p0) && !Moves(p1)) {
      // A ground body adds no row, but its fixed points must agree with its shape.
      CheckFixedBody(body);
      return;
    }
    ConstraintRow d;
    d.kind = RowKind::kBodyDistance;
    d.element = what;
    d.src = body.src;
    d.pts = {p0, p1, -1};
    d.L = L;
    d.scale = L * L;
    out_.rows.push_back(d);
    for (size_t k = 2; k < body.points.size(); ++k) {
      const int pk = body.points[k];
      ConstraintRow row;
      row.element = what + " point " + m_.points[pk].name;
      row.src = body.src;
      row.pts = {p0, p1, pk};
      row.a = body.p_B[k].x() / L;
      row.b = body.p_B[k].y() / L;
      row.L = L;
      row.scale = L;
      row.kind = RowKind::kBodyLinearX;
      out_.rows.push_back(row);
      row.kind = RowKind::kBodyLinearY;
      out_.rows.push_back(row);
    }
  }

  void CheckFixedBody(const Body& body) {
    const Eigen::Vector2d o = out_.point_const[body.points[0]];
    const Eigen::Vector2d ex = (out_.point_const[body.points[1]] - o) / body.Length();
    const Eigen::Vector2d ey(-ex.y(), ex.x());
    for (size_t k = 1; k < body.points.size(); ++k) {
      const int p = body.points[k];
      if (Moves(p)) continue;  // a moving point of a grounded body still gets its linear rows
      const Eigen::Vector2d expect = o + body.p_B[k].x() * ex + body.p_B[k].y() * ey;
      if ((expect - out_.point_const[p]).norm() > 1e-9 * out_.length_scale)
        throw ScenarioError(body.src, "body " + body.name + " joins fixed points that do not fit its shape",
                            "check the fixed points' positions and the body's length/shape");
    }
  }

  void JointRows(const Joint& j) {
    if (j.type == JointType::kGear) {
      GearRow(j);
      return;
    }
    const bool both = out_.point_slot[j.point][0] >= 0 && out_.point_slot[j.point][1] >= 0;
    if (j.type == JointType::kPointOnFixedLine && !both) return;  // eliminated: no row
    if (!Moves(j.point)) return;                                   // nothing to constrain
    ConstraintRow row;
    row.kind = RowKind::kPointOnLine;
    row.element = j.name.empty() ? "slider" : j.name;
    row.src = j.src;
    std::array<int, 2> line = j.line;
    if (j.type == JointType::kPointOnBody) {
      const Body& b = m_.bodies[j.body];
      if (b.points.size() < 2)
        throw ScenarioError(j.src, row.element + ": body " + b.name + " has no line", "give it two points");
      line = {b.points[0], b.points[1]};
      row.scale = b.Length() * out_.length_scale;
    } else {
      row.scale = (out_.point_const[line[1]] - out_.point_const[line[0]]).norm() * out_.length_scale;
    }
    if (line[0] < 0 || line[1] < 0) throw ScenarioError(j.src, row.element + " has no guide line");
    if (!(row.scale > 0))
      throw ScenarioError(j.src, row.element + ": the guide's two points coincide", "use two distinct points");
    row.pts = {j.point, line[0], line[1]};
    out_.rows.push_back(row);
  }

  int MemberSlot(int body, const Joint& j) const {
    const int s = out_.member_slot[body];
    if (s < 0)
      throw ScenarioError(j.src, "gear member " + m_.bodies[body].name + " has no rotation coordinate",
                          "add a coordinate {type: rotation, member: " + m_.bodies[body].name + "}");
    return s;
  }

  void GearRow(const Joint& j) {
    ConstraintRow row;
    row.kind = RowKind::kGear;
    row.element = j.name.empty() ? "gear" : j.name;
    row.src = j.src;
    row.slots = {MemberSlot(j.members[0], j), MemberSlot(j.members[1], j),
                 j.carrier >= 0 ? MemberSlot(j.carrier, j) : -1};
    row.z_a = j.teeth[0];
    row.z_b = (j.internal ? -1.0 : 1.0) * j.teeth[1];
    // The mesh keeps the phase of the guesses: c = Z_a(φ_a − φ_c) + s Z_b(φ_b − φ_c) at the guess.
    const Eigen::VectorXd q0 = m_.GuessQ();
    const double phi_c = row.slots[2] >= 0 ? q0[row.slots[2]] : 0.0;
    row.c = row.z_a * (q0[row.slots[0]] - phi_c) + row.z_b * (q0[row.slots[1]] - phi_c);
    row.scale = j.teeth[0] + j.teeth[1];
    out_.rows.push_back(row);
  }

  // q_b − k q_a − c: linear in q, so its Jacobian row is constant and Φ̇_q q̇ is zero.
  void CouplingRow(const Coupling& c) {
    MB_ASSERT(c.slots[0] >= 0 && c.slots[1] >= 0 && c.slots[0] < out_.n && c.slots[1] < out_.n, "coupling without slots");
    ConstraintRow row;
    row.kind = RowKind::kCoupling;
    row.element = c.name;
    row.src = c.src;
    row.slots = {c.slots[0], c.slots[1], -1};
    row.k = c.ratio;
    row.c = c.offset;
    row.scale = std::max(out_.q_scale[c.slots[1]], std::fabs(c.ratio) * out_.q_scale[c.slots[0]]);
    out_.rows.push_back(row);
  }

  // |b − a| if the two points keep a constant distance (both fixed, or both in one body).
  std::optional<double> PairLength(int a, int b) const {
    if (!Moves(a) && !Moves(b)) return (out_.point_const[b] - out_.point_const[a]).norm();
    for (const Body& body : m_.bodies) {
      const auto ia = std::find(body.points.begin(), body.points.end(), a);
      const auto ib = std::find(body.points.begin(), body.points.end(), b);
      if (ia == body.points.end() || ib == body.points.end()) continue;
      return (body.p_B[ib - body.points.begin()] - body.p_B[ia - body.points.begin()]).norm();
    }
    return std::nullopt;
  }

  double RequireLength(const Coordinate& c, const std::array<int, 2>& pair, const std::string& what) const {
    const auto L = PairLength(pair[0], pair[1]);
    if (!L)
      throw ScenarioError(c.src,
                          what + ": points " + m_.points[pair[0]].name + " and " + m_.points[pair[1]].name +
                              " are not on one body, so their distance is not a constant of the row",
                          "use form: cross, or make the vector a body's points");
    if (!(*L > 0)) throw ScenarioError(c.src, what + ": the vector has zero length");
    return *L;
  }

  void CoordinateRows(int ci) {
    const Coordinate& c = m_.coordinates[ci];
    const int slot = out_.coordinate_slot[ci];
    MB_ASSERT(slot >= 0, "coordinate without a slot");
    ConstraintRow row;
    row.src = c.src;
    row.slots = {slot, -1, -1};
    row.pts = {c.vec[0], c.vec[1], -1};
    row.ref = c.ref;
    const std::string what = "coordinate " + c.name;
    switch (c.type) {
      case CoordinateType::kRotation:
      case CoordinateType::kTravel:
        return;  // a member's rotation or a rack's travel is itself the coordinate (a rack row ties it)
      case CoordinateType::kDistance:
        row.kind = RowKind::kDistance;
        row.element = what + " (distance)";
        row.scale = out_.length_scale * out_.length_scale;
        out_.rows.push_back(row);
        return;
      case CoordinateType::kAngle:
        break;
    }
    const bool ground = c.ref[0] < 0;
    switch (c.form) {
      case AngleForm::kCos:
      case AngleForm::kSin:
      case AngleForm::kCosSin: {
        if (!ground)
          throw ScenarioError(c.src, what + ": cos/sin forms measure from the ground x axis",
                              "remove the reference or use form: dot or cross");
        row.L = RequireLength(c, c.vec, what);
        row.scale = row.L;
        if (c.form != AngleForm::kSin) {
          row.kind = RowKind::kAngleCos;
          row.element = what + " (cos)";
          out_.rows.push_back(row);
        }
        if (c.form != AngleForm::kCos) {
          row.kind = RowKind::kAngleSin;
          row.element = what + " (sin)";
          out_.rows.push_back(row);
        }
        return;
      }
      case AngleForm::kDot: {
        if (ground)
          throw ScenarioError(c.src, what + ": the dot form needs a reference vector", "add reference: [P, Q]");
        row.kind = RowKind::kAngleDot;
        row.element = what + " (dot)";
        row.L = RequireLength(c, c.ref, what) * RequireLength(c, c.vec, what);
        row.scale = row.L;
        out_.rows.push_back(row);
        return;
      }
      case AngleForm::kCross: {
        row.kind = RowKind::kAngleCross;
        row.element = what + " (cross)";
        // The cross form needs no constant length; its scale is the vectors' size at the guess.
        const auto len = [&](const std::array<int, 2>& pair) {
          if (pair[0] < 0) return 1.0;
          const auto L = PairLength(pair[0], pair[1]);
          const double g = (m_.points[pair[1]].p_W - m_.points[pair[0]].p_W).norm();
          return L ? *L : (std::isfinite(g) && g > 0 ? g : out_.length_scale);
        };
        row.scale = len(c.ref) * len(c.vec);
        out_.rows.push_back(row);
        return;
      }
    }
  }

  void Drivers() {
    for (const Driver& d : m_.drivers) {
      const int s = m_.SlotIndex(d.coordinate);
      if (s < 0)
        throw ScenarioError(d.src, "driver names '" + d.coordinate + "', which is not in q",
                            "drive a coordinate of the layout");
      if (!std::isfinite(d.value))
        throw ScenarioError(d.src, "driver of " + d.coordinate + " has no value", "give value: at t0");
      out_.drivers.push_back({s, d});
    }
  }

  const Model& m_;
  NaturalModel out_;
};

}  // namespace

NaturalModel Compile(const Model& model) {
  if (model.kind == ScenarioKind::kSpatial) return CompileSpatial(model);  // spatial_compile.cc
  return Compiler(model).Run();
}

}  // namespace mechbench::numeric
