// SPDX-License-Identifier: MIT
/// @file friction_model.hpp
/// Which friction law ODE applies at a contact: the per-axis pyramid of stock ODE, or the
/// circular cone of the patched ODE that rheofeed builds (patches/0002-quickstep-friction-cone).
///
/// Stock ODE limits a contact's two friction impulses each on its own, |f_i| <= mu N (with
/// dContactApprox1): up to sqrt(2) mu N on a diagonal, and a part sliding along one axis keeps
/// the full capacity of the other (on a cross slope it never creeps sideways). The cone limits
/// them together, |f_t| <= mu N, as Coulomb's law and the paper's cone complementarity do. The
/// cone is a surface mode bit (dContactFrictionCone, 0x8000) that only the patched library reads:
/// a stock library would ignore it silently, so rheofeed refuses to ask for it there
/// (requireFrictionModel), and only dWorldQuickStep solves it (the patched dWorldStep refuses a
/// world holding such a contact: the Dantzig LCP cannot express a cone).
#pragma once

#include <ode/ode.h>

namespace rheofeed {

/// The friction law of a contact.
enum class FrictionModel {
  Pyramid,  ///< stock ODE: each friction row clamped to mu N on its own (ODE's default)
  Cone,     ///< the two rows limited together to the disc of radius mu N (patched ODE only)
};
/// Printable name: "pyramid" or "cone".
inline const char* toString(FrictionModel model) {
  return model == FrictionModel::Cone ? "cone" : "pyramid";
}
/// The model named `name` ("cone" or "pyramid"); false for any other name.
inline bool parseFrictionModel(const char* name, FrictionModel& model) {
  const char* names[] = {"pyramid", "cone"};
  for (int k = 0; k < 2; ++k) {
    const char* a = name;
    const char* b = names[k];
    while (*a && *a == *b) ++a, ++b;
    if (*a == *b) {
      model = k == 1 ? FrictionModel::Cone : FrictionModel::Pyramid;
      return true;
    }
  }
  return false;
}

/// ODE's surface mode bit for the cone (dContactFrictionCone of the patched contact.h). It is
/// defined here too so that rheofeed compiles against stock headers; a stock library ignores it.
constexpr int kContactFrictionCone = 0x8000;

/// Whether the ODE library linked at run time has the cone: dCheckConfiguration(
/// "ODE_EXT_friction_cone"), the token the patch adds to dGetConfiguration().
bool odeHasFrictionCone();

/// Throws std::invalid_argument when `model` is Cone and the linked ODE has no cone; the message
/// names `setting` (e.g. "FeederSet::Options::friction") and the library's configuration.
void requireFrictionModel(FrictionModel model, const char* setting);

/// Sets (Cone) or clears (Pyramid) kContactFrictionCone in a surface mode.
inline int withFrictionModel(int mode, FrictionModel model) {
  return model == FrictionModel::Cone ? (mode | kContactFrictionCone)
                                      : (mode & ~kContactFrictionCone);
}

}  // namespace rheofeed
