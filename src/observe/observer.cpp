#include "sheardiff/observe/observer.hpp"

#include <algorithm>

#include "sheardiff/io/summary_keys.hpp"

namespace sheardiff {

template <class D>
std::vector<std::string> RheologyObserverOf<D>::frame_names() const {
  return {"strain", "shear_stress", "pressure", "sigma_xx", "sigma_yy", "contacts", "max_overlap"};
}

template <class D>
std::vector<std::string> RheologyObserverOf<D>::frame_units() const {
  return {"1", "P", "P", "P", "P", "1", "d"};
}

template <class D>
void RheologyObserverOf<D>::on_frame(const StepView& v, std::vector<double>& values) {
  const StressSample& s = v.stress;
  values.insert(values.end(), {v.dynamics.strain(), s.shear_stress(), s.pressure(), s.sxx, s.syy,
                               static_cast<double>(s.contacts), s.max_overlap});
}

template <class D>
void RheologyObserverOf<D>::on_step(const StepView& v) {
  const StressSample& s = v.stress;
  max_overlap_ = std::max(max_overlap_, s.max_overlap);
  if (v.dynamics.strain() <= transient_) return;
  weight_ += v.dt;
  sxy_ += v.dt * s.shear_stress();
  pressure_ += v.dt * s.pressure();
  contacts_ += v.dt * s.contacts;
  mean_overlap_ += v.dt * s.mean_overlap;
}

template <class D>
void RheologyObserverOf<D>::finish(const Dynamics& d, nlohmann::json& js, H5mdWriter*) {
  js[summary_key::max_overlap] = max_overlap_;
  js[summary_key::averaged_from_strain] = transient_;
  if (weight_ <= 0.0) {
    // Nothing to average: the run ended before run.transient_strain.
    for (const char* k :
         {summary_key::mean_overlap, summary_key::shear_stress, summary_key::pressure,
          summary_key::contacts_per_particle, summary_key::viscosity})
      js[k] = nullptr;
    return;
  }
  const double w = weight_;
  js[summary_key::mean_overlap] = mean_overlap_ / w;
  js[summary_key::shear_stress] = sxy_ / w;
  js[summary_key::pressure] = pressure_ / w;
  js[summary_key::contacts_per_particle] =
      contacts_ / w / static_cast<double>(d.particles().n_mobile);
  js[summary_key::viscosity] = d.flow().gammadot > 0 ? sxy_ / w / d.flow().gammadot : 0.0;
}

template class RheologyObserverOf<Dim2>;
template class RheologyObserverOf<Dim3>;

}  // namespace sheardiff
