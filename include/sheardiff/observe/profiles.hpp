#pragma once
// Profiles across the gap of a scene with walls (docs/model.md section 9): phi(y), u_x(y), the
// fluctuation temperature T(y) = <u'.u'> and the stresses sigma_xy(y) and p(y), in bins measured
// from the bottom wall's centre line, averaged over the run's measured window.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/observe/observer.hpp"

namespace sheardiff {

// Area of the disc (centre height yc, radius a) lying between heights y1 < y2.
double disc_area_between(double yc, double a, double y1, double y2);
// Volume of the sphere (centre height yc, radius a) lying between heights y1 < y2.
double sphere_volume_between(double yc, double a, double y1, double y2);
// The part of a particle between two heights: a disc's area, a sphere's volume.
template <class D>
double measure_between(double yc, double a, double y1, double y2) {
  if constexpr (D::space == 3) return sphere_volume_between(yc, a, y1, y2);
  return disc_area_between(yc, a, y1, y2);
}

// The profiles' accumulators, with any weight (dt during a run, 1 per frame when recomputed
// from a trajectory).
class GapProfiles {
 public:
  explicit GapProfiles(double bin) : bin_(bin) {}
  // phi, u_x and T from the mobile particles and their velocities u; y_bottom: the bottom
  // wall's centre line, height: the gap, section: the cell's extent normal to y (band_section).
  template <class D>
  void add(const ParticlesOf<D>& p, const std::vector<typename D::Body>& u, double y_bottom,
           double height, double section, double weight);
  // The pair stresses of the step (sigma = -sum l n f / V): each pair's share in the bin of its
  // midpoint; lz: the monolayer's thickness (discs). With lubrication, also the part of them
  // its forces make (the rest is the contacts' springs, and the repulsion where it is on).
  // Summed over the step's stages (StageOf), each with its own pair terms and velocities.
  template <class D>
  void add_stress(const DynamicsOf<D>& d, const std::vector<StageOf<D>>& stages, double y_bottom,
                  double lz, double weight);
  bool empty() const { return w_.empty(); }
  // Rows = bins; columns y (bin centre), phi, u_x, T.
  Eigen::MatrixXd table() const;
  // The table into summary: profile_{y, phi, u_x, T} with velocities over gammadot (and, when
  // measured, profile_shear_stress and profile_pressure in P, and their lubrication parts when
  // measured over the whole window), and the shear rate of the bulk (a line fit of u_x over the
  // bins at least `exclusion` from both walls) over the imposed gammadot = V / H.
  void to_summary(nlohmann::json& js, double gammadot, double height, double exclusion) const;
  void serialize(Archive& a) {
    a.io(section_);
    for (auto* v : {&w_, &area_, &n_, &ux_, &ux2_, &uy2_, &sxy_, &sp_}) a.io(*v);
    if (!a.loading() || a.layout() >= 9) {
      for (auto* v : {&sxy_lub_, &sp_lub_}) a.io(*v);
      a.io(lubrication_partial_);
    } else {
      // Layout 8 and earlier kept no lubrication part: a window already under way when such a
      // checkpoint was written has its lubrication part over only what follows, so none is
      // reported.
      lubrication_partial_ = std::any_of(w_.begin(), w_.end(), [](double w) { return w > 0.0; });
    }
  }

 private:
  template <class D>
  void add_stage_stress(const DynamicsOf<D>& d, const std::vector<PairTermOf<D>>& terms,
                        const VelocitiesOf<D>& v, double y_bottom, double volume, double weight);
  void grow(std::size_t bins);
  double bin_, section_ = 1.0;  // the cell's extent normal to y (lx, or lx lz for spheres)
  std::vector<double> w_, area_, n_, ux_, ux2_, uy2_, sxy_, sp_;
  std::vector<double> sxy_lub_, sp_lub_;  // the lubrication forces' part of sxy_, sp_
  bool lubrication_partial_ = false;      // resumed from a layout without it, mid-window
};

// The profiles as an observer of any scene with walls, over the measured window.
template <class D>
class ProfilesObserverOf final : public ObserverOf<D> {
 public:
  using typename ObserverOf<D>::Dynamics;
  using typename ObserverOf<D>::StepView;

  ProfilesObserverOf(const Config& cfg, MeasuredWindowOf<D> measuring)
      : profiles_(cfg.observables.profile_bin),
        exclusion_(cfg.observables.wall_exclusion),
        lz_(cfg.flow.lz),
        measuring_(std::move(measuring)) {}
  void on_step(const StepView& v) override;
  void finish(const Dynamics& d, nlohmann::json& summary, H5mdWriter* writer) override;
  void serialize(Archive& a) override {
    a.tag("profiles");
    a.io(w_), a.io(h_);
    profiles_.serialize(a);
  }

 private:
  GapProfiles profiles_;
  double exclusion_, lz_;
  MeasuredWindowOf<D> measuring_;
  double w_ = 0.0, h_ = 0.0;  // measured time and time integral of the gap
};

using ProfilesObserver = ProfilesObserverOf<Dim2>;

}  // namespace sheardiff
