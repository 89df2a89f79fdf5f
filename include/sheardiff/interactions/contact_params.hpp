#pragma once
// The frictional contact law's parameters and their keys, declared once: the configuration
// schema, its validation and docs/config.md read them from here (interactions/contact.hpp is
// the law).
#include <string>

namespace sheardiff {

struct ContactParams {
  double ktilde = 1e4;
  double kt_ratio = 0.5;
  double mu = 0.5;
  std::string stiffness = "uniform";     // or "mean_radius" (kn, kt x (a_i + a_j) / d)
  std::string stick_rule = "unloading";  // or "coulomb" (FrictionalContact::StickRule)
  // Or "sideways" (FrictionalContact::sideways), a config file's default for spheres
  // (ConfigSource).
  std::string sliding_stiffness = "none";

  // Keys: the schema's section adapter (src/config.cpp), with real / boolean / choice.
  template <class Keys>
  static void declare(Keys& k) {
    k.real("contact.ktilde", &ContactParams::ktilde, 1.0, 1e9, false, "P d (so kn = ktilde)",
           "Normal contact stiffness kn / (P d).");
    k.real("contact.kt_ratio", &ContactParams::kt_ratio, 0.0, 1.0, false, "",
           "Tangential over normal stiffness kt / kn.");
    k.real("contact.mu", &ContactParams::mu, 0.0, 10.0, false, "",
           "Coulomb friction coefficient (0 = frictionless, no tangential springs).");
    k.choice("contact.stiffness", {"uniform", "mean_radius"}, &ContactParams::stiffness,
             "Per-pair stiffness: `uniform` (every pair kn, kt) or `mean_radius` (LF_DEM's "
             "convention: kn, kt times (a_i + a_j) / d, so 1.2x for small-large and 1.4x for "
             "large-large pairs at size_ratio 1.4).");
    k.choice("contact.stick_rule", {"unloading", "coulomb"}, &ContactParams::stick_rule,
             "Implicit springs: which sliding contacts stick once the step's slip s is solved "
             "(docs/model.md section 7). `unloading`: every one whose slip runs against its "
             "stretch xi (xi . s < 0). `coulomb`: one whose trial stretch xi + s dt ends inside "
             "the Coulomb cone, or whose slip along -xi carries the stretch through zero (a "
             "reversal that would otherwise flip between opposite caps). The same test for "
             "discs; for spheres `coulomb` leaves sliding a contact whose slip turns it sideways "
             "without bringing it inside the cone.");
    k.choice("contact.sliding_stiffness", {"none", "sideways"}, &ContactParams::sliding_stiffness,
             "Implicit springs between spheres: the tangential stiffness a sliding contact puts "
             "in the matrix (docs/model.md section 7). `none`: none, so the direction of its "
             "friction force is explicit. `sideways`: across its stretch, kt times the ratio "
             "cap / |trial stretch| of its last Coulomb cap (the capped spring's tangent), so "
             "that the force turns with the slip within the step. Discs have no sideways "
             "direction: for them the two are the same law. Spheres default to `sideways`, the "
             "law closer to a finer step (docs/results-3d.md, \"The sliding law\"); a run's "
             "record (DIR/config.toml) that does not name the key predates it and ran `none`.");
  }
};

}  // namespace sheardiff
