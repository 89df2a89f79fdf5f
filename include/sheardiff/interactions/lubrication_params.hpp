#pragma once
// The lubrication law's parameters and their keys, declared once: the configuration schema, its
// validation and docs/config.md read them from here (interactions/lubrication.hpp is the law).
#include <string>

namespace sheardiff {

struct LubricationParams {
  bool enabled = true;
  double delta = 0.01;
  double h_max = 0.5;
  bool tangential = true;  // shear, shear-rotation and pump modes (off: squeeze only)

  // Keys: the schema's section adapter (src/config.cpp), with real / boolean / choice.
  template <class Keys>
  static void declare(Keys& k) {
    k.boolean("lubrication.enabled", &LubricationParams::enabled,
              "Pairwise lubrication and lubrication-matched contact dashpots.");
    // The squeeze resistance at contact grows as 1/delta: at delta = 1e-20 the resistance
    // matrix is no longer positive definite in double precision (measured).
    k.real("lubrication.delta", &LubricationParams::delta, 1e-10, 0.5, false, "1 (reduced gap)",
           "Regularisation of the lubrication singularity.");
    k.real("lubrication.h_max", &LubricationParams::h_max, 0.0, 1.0, true, "1 (reduced gap)",
           "Lubrication cut-off: active for 0 < h < h_max (must be < 1).", /*hi_open=*/true);
    k.boolean("lubrication.tangential", &LubricationParams::tangential,
              "Tangential lubrication modes (shear, shear-rotation, pump); off = squeeze "
              "only. Off with mu = 0: no rotational unknowns (2 per particle).");
  }
};

}  // namespace sheardiff
