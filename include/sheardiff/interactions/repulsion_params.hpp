#pragma once
// The double-layer repulsion's parameters and their keys, declared once: the configuration
// schema, its validation and docs/config.md read them from here (interactions/repulsion.hpp
// is the law).
namespace sheardiff {

struct RepulsionParams {
  double f0 = 0.0;       // P d^2; 0 = off
  double lambda = 0.02;  // Debye length, d
  double cutoff = 10.0;  // in Debye lengths

  // Keys: the schema's section adapter (src/config.cpp), with real / boolean / choice.
  template <class Keys>
  static void declare(Keys& k) {
    k.real("repulsion.F0", &RepulsionParams::f0, 0.0, 1e4, false, "P d^2",
           "Electrostatic double-layer repulsion F0 exp(-h / lambda) between the "
           "surfaces (h the gap, along the line of centres; F0 when touching); 0 = off.");
    k.real("repulsion.lambda", &RepulsionParams::lambda, 0.0, 0.5, true, "d",
           "Debye length lambda of the double-layer repulsion.");
    k.real("repulsion.cutoff", &RepulsionParams::cutoff, 1.0, 20.0, false, "lambda",
           "Gap, in Debye lengths, beyond which the repulsion is cut "
           "(where it has fallen to exp(-cutoff) F0).");
  }
};

}  // namespace sheardiff
