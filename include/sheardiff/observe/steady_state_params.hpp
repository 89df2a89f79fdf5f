#pragma once
// The pressure cell's steady-state test and stationarity judgement (observe/pressure_cell.hpp):
// their parameters and keys, declared once; the configuration schema, its validation and
// docs/config.md read them from here.
namespace sheardiff {

struct SteadyStateParams {
  double window = 2.0;                // strain window of the no-drift test
  double h_tolerance = 0.01;          // relative drift of H allowed between the window halves
  double mu_tolerance = 0.05;         // drift of mu allowed between the window halves
  double measure_strain = 0.0;        // strain run after steady state (0 = until run.strain)
  double drift_z = 3.0;               // standard errors a window's drift signals may reach
  double bulk_load_tolerance = 0.05;  // of P, for the bulk's -sigma_yy

  // Keys: the schema's section adapter (src/config.cpp).
  template <class Keys>
  static void declare(Keys& k) {
    using P = SteadyStateParams;
    k.real("steady.window", &P::window, 0.0, 1e4, true, "1 (strain)",
           "pressure_shear: steady state = no drift of H and mu between the two halves of the "
           "last window of this strain.");
    k.real("steady.h_tolerance", &P::h_tolerance, 0.0, 1.0, true, "",
           "Relative change of mean H allowed between the window halves.");
    k.real("steady.mu_tolerance", &P::mu_tolerance, 0.0, 10.0, true, "",
           "Change of mean mu allowed between the window halves.");
    k.real("steady.drift_z", &P::drift_z, 0.0, 100.0, true, "",
           "pressure_shear: the measured window is stationary when the net y drag on the discs, "
           "mu_top - mu_bottom and the change of H across it are each zero within this many "
           "standard errors (time blocks of analysis.error_block).");
    k.real("steady.bulk_load_tolerance", &P::bulk_load_tolerance, 0.0, 1.0, true, "",
           "pressure_shear: ... and when -sigma_yy of the pair forces in the bulk is P within "
           "this fraction.");
    k.real("steady.measure_strain", &P::measure_strain, 0.0, 1e5, false, "1 (strain)",
           "pressure_shear: strain simulated after steady state, then stop (0 = run to "
           "run.strain; run.strain always caps the run).");
  }
};

}  // namespace sheardiff
