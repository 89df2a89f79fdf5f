#pragma once
// The channel scene's parameters and their keys, declared once: the configuration schema, its
// validation and docs/config.md read them from here (src/scene/channel.cpp is the scene).
#include <cstdint>
#include <string>

namespace sheardiff {

struct ChannelParams {
  double phi = 0.4;                  // bulk areal fraction
  double h_over_a = 18.32;           // H / a, between the wall rows' surfaces
  std::int64_t wall_discs = 9;       // discs per wall row; Lx = wall_discs d
  double mean_velocity = 1.0;        // <u>, P d / eta
  std::string coupling = "two_way";  // or "one_way" (a fixed Poiseuille background)
  std::int64_t fluid_cells = 0;      // elements across H; 0 = one per a/2
  double sample_interval = 20.0;     // a / <u>
  double steady_window = 800.0;      // a / <u>
  double steady_tolerance = 0.02;    // of the centreline distance, between window halves

  // Keys: the schema's section adapter (src/config.cpp), with real / integer / choice.
  template <class Keys>
  static void declare(Keys& k) {
    using P = ChannelParams;
    k.real("channel.phi", &P::phi, 0.0, 0.6, true, "",
           "channel: bulk areal fraction of the mobile discs over the area Lx H between the wall "
           "rows (the seed's phi_b).");
    k.real("channel.h_over_a", &P::h_over_a, 4.0, 400.0, false, "a",
           "channel: width H over the disc radius a, H between the surfaces of the two wall rows "
           "(the seed's shortest distance between the walls).");
    k.integer("channel.wall_discs", &P::wall_discs, 3, 1e5, "",
              "channel: touching discs per wall row; the periodic length is Lx = wall_discs d "
              "(the seed's N_w).");
    k.real("channel.mean_velocity", &P::mean_velocity, 0.0, 1e3, true, "P d / eta",
           "channel: mean velocity <u> of the fluid across the channel, held fixed by the "
           "pressure gradient (an output).");
    k.choice("channel.coupling", {"two_way", "one_way"}, &P::coupling,
             "channel: two_way = the fluid's mean profile U_f(y) is solved with the particles "
             "each step (it blunts with them; the pressure gradient is an output); one_way = a "
             "fixed Poiseuille background that the particles do not change.");
    k.integer("channel.fluid_cells", &P::fluid_cells, 0, 1e5, "",
              "channel: linear elements of the fluid profile across H; 0 = one per a/2 (the "
              "seed's profile bins), at least 4.");
    k.real("channel.sample_interval", &P::sample_interval, 0.0, 1e6, true, "a / <u>",
           "channel: time between two rows of the profile history (profiles averaged over each "
           "interval, pressure gradient, centreline distance).");
    k.real("channel.steady_window", &P::steady_window, 0.0, 1e7, true, "a / <u>",
           "channel: migration is steady when the mean distance of the discs from the centreline "
           "drifts less than channel.steady_tolerance between the two halves of the last window "
           "of this length.");
    k.real("channel.steady_tolerance", &P::steady_tolerance, 0.0, 1.0, true, "",
           "channel: relative drift allowed (see channel.steady_window).");
  }
};

}  // namespace sheardiff
