// SPDX-License-Identifier: MIT
#include "geom_factory.hpp"

#include <stdexcept>
#include <string>

namespace rheofeed::scene {

dGeomID createGeom(dSpaceID space, const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Box:
      return dCreateBox(space, s.size.x, s.size.y, s.size.z);
    case Shape::Kind::Sphere:
      return dCreateSphere(space, s.radius);
    case Shape::Kind::Cylinder:
      return dCreateCylinder(space, s.radius, s.length);
    case Shape::Kind::Capsule:
      return dCreateCapsule(space, s.radius, s.length);
    case Shape::Kind::Plane:
      return dCreatePlane(space, s.plane_normal.x, s.plane_normal.y, s.plane_normal.z,
                          s.plane_offset);
    case Shape::Kind::Mesh:
      throw std::invalid_argument("mesh '" + s.mesh + "': mesh shapes are not supported yet");
  }
  throw std::invalid_argument("unknown shape kind");
}

void setGeomPose(dGeomID geom, const Pose& pose) {
  dGeomSetPosition(geom, pose.position.x, pose.position.y, pose.position.z);
  dMatrix3 r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r[4 * i + j] = pose.rotation[3 * i + j];
    r[4 * i + 3] = 0;
  }
  dGeomSetRotation(geom, r);
}

}  // namespace rheofeed::scene
