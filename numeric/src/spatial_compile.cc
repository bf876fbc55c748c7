// A spatial scene file compiled to natural coordinates (spatial.h, CompileSpatial): the loader
// has checked the file (unit vectors, non-coplanar bases, points on their lines, inertia), and
// its pose is an assembled one, from which SpatialBuilder reads every constant.
#include "mechbench/errors.h"
#include "mechbench/numeric/spatial.h"

namespace mechbench::numeric {

NaturalModel CompileSpatial(const Model& model) {
  MB_ASSERT(model.kind == ScenarioKind::kSpatial, "CompileSpatial on a planar scene");
  const SpatialModel& s = model.spatial;
  SpatialBuilder b;
  // Entities in file order (points, then vectors): the moving ones take their q slots in the
  // same order as Model::q_layout.
  std::vector<int> ent(s.entities.size());
  for (size_t e = 0; e < s.entities.size(); ++e) {
    const SpatialEntity& x = s.entities[e];
    ent[e] = x.vector ? b.Vector(x.name, x.r_W.normalized(), x.fixed) : b.Point(x.name, x.r_W, x.fixed);
  }
  std::vector<int> coordinate_slot(s.coordinates.size());
  for (size_t c = 0; c < s.coordinates.size(); ++c)
    coordinate_slot[c] = b.Coordinate(s.coordinates[c].name, s.coordinates[c].value, !s.coordinates[c].IsAngle());
  MB_ASSERT(b.n() == static_cast<int>(model.q_layout.size()), "the spatial q layout and the builder's slots differ");

  // A point mass's element is a rigid body's on its point and the fixed world axes (constant: they
  // add no row and no slot), with its centre of mass at the point and no inertia.
  // Each row's source: the body, joint, coordinate or driver of the file that gave it (a message
  // on a row, e.g. the redundant ones, names its line).
  std::vector<SourceRef> row_src;
  const auto from = [&](const SourceRef& src) {
    while (static_cast<int>(row_src.size()) < b.rows())
      row_src.push_back(SourceRef{model.source_file, src.line});
  };
  std::array<int, 3> world{-1, -1, -1};
  const auto world_axes = [&] {
    if (world[0] < 0)
      for (int k = 0; k < 3; ++k) world[k] = b.Vector(std::string("world ") + "xyz"[k], Eigen::Vector3d::Unit(k), true);
    return world;
  };
  for (const SpatialBody& body : s.bodies) {
    const double mass = body.HasMass() ? body.mass : 0.0;
    if (body.entities.size() == 1) {
      if (mass > 0) {
        const auto w = world_axes();
        b.Body(body.name, {ent[body.entities[0]], w[0], w[1], w[2]}, mass, s.entities[body.entities[0]].r_W);
      }
    } else if (body.entities.size() == 2) {  // a bar: a slender uniform rod when it has mass
      b.Bar(body.name, ent[body.entities[0]], ent[body.entities[1]], mass);
    } else {
      const std::array<int, 4> basis{ent[body.entities[0]], ent[body.entities[1]], ent[body.entities[2]], ent[body.entities[3]]};
      const int k = b.Body(body.name, basis, mass, body.HasMass() ? body.com_W : s.entities[body.entities[0]].r_W,
                           body.inertia_W);
      for (size_t e = 4; e < body.entities.size(); ++e) b.Attach(k, ent[body.entities[e]]);
    }
    from(body.src);
  }
  for (const SpatialJoint& j : s.joints) {
    if (j.type == SpatialJoint::Type::kDistance) {
      b.Distance(ent[j.a[0]], ent[j.a[1]]);
    } else {
      const auto id = [&](int e) { return e < 0 ? -1 : ent[e]; };
      b.Dot(id(j.a[0]), id(j.a[1]), id(j.b[0]), id(j.b[1]));
    }
    from(j.src);
  }
  for (size_t c = 0; c < s.coordinates.size(); ++c) {
    const SpatialCoordinate& x = s.coordinates[c];
    if (x.IsAngle())
      b.Angle(ent[x.from], ent[x.to], ent[x.direction], coordinate_slot[c]);
    else
      b.PointOnLine(ent[x.point], ent[x.from], ent[x.direction], -1, coordinate_slot[c]);
    from(x.src);
  }
  for (const Driver& d : model.drivers) {
    const int slot = model.SlotIndex(d.coordinate);
    MB_ASSERT(slot >= 0, "a driver on a coordinate the loader did not check");
    b.Drive(slot, d);
    from(d.src);
  }
  b.Gravity(s.gravity);
  NaturalModel nm = b.Build();
  nm.model = model;  // the file's scene, with its q layout (the same slots, the file's names)
  nm.meters_per_unit = model.length_unit == "mm" ? 1e-3 : model.length_unit == "cm" ? 1e-2 : 1.0;
  from(SourceRef{});
  MB_ASSERT(row_src.size() == nm.rows.size(), "a spatial row without its source");
  for (size_t i = 0; i < nm.rows.size(); ++i)
    nm.rows[i].src = model.source_file.empty() ? SourceRef{} : row_src[i];
  return nm;
}

}  // namespace mechbench::numeric
