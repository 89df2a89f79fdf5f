#include "sheardiff/config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <variant>

#include "sheardiff/core/text.hpp"
#include "sheardiff/scene/registry.hpp"

namespace sheardiff {

const char* to_string(IntegratorType t) {
  switch (t) {
    case IntegratorType::Implicit:
      return "implicit";
    case IntegratorType::Euler:
      return "euler";
    case IntegratorType::Heun:
      return "heun";
  }
  return "?";
}
const char* to_string(MixRule m) {
  switch (m) {
    case MixRule::Area:
      return "area";
    case MixRule::Volume:
      return "volume";
    case MixRule::Number:
      return "number";
  }
  return "?";
}

namespace {

using Value = std::variant<double, std::int64_t, bool, std::string, std::vector<double>>;

enum class Kind { Real, Integer, Boolean, Text, Choice, RealList };

struct KeySpec {
  std::string key;  // "section.name"
  Kind kind;
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;  // lo excluded
  bool hi_open = false;  // hi excluded
  std::vector<std::string> choices;
  std::string unit;
  std::string doc;
  std::function<Value(const Config&)> get;
  std::function<void(Config&, const Value&)> set;
};

constexpr double kInf = std::numeric_limits<double>::infinity();

template <typename T>
KeySpec real(std::string key, T Config::*sec, double T::*field, double lo, double hi, bool lo_open,
             std::string unit, std::string doc, bool hi_open = false) {
  KeySpec k{std::move(key),  Kind::Real,     lo, hi, lo_open, hi_open, {},
            std::move(unit), std::move(doc), {}, {}};
  k.get = [sec, field](const Config& c) { return Value{c.*sec.*field}; };
  k.set = [sec, field](Config& c, const Value& v) { c.*sec.*field = std::get<double>(v); };
  return k;
}
template <typename T>
KeySpec integer(std::string key, T Config::*sec, std::int64_t T::*field, double lo, double hi,
                std::string unit, std::string doc) {
  KeySpec k{std::move(key),  Kind::Integer,  lo, hi, false, false, {},
            std::move(unit), std::move(doc), {}, {}};
  k.get = [sec, field](const Config& c) { return Value{c.*sec.*field}; };
  k.set = [sec, field](Config& c, const Value& v) { c.*sec.*field = std::get<std::int64_t>(v); };
  return k;
}
template <typename T>
KeySpec boolean(std::string key, T Config::*sec, bool T::*field, std::string doc) {
  KeySpec k{
      std::move(key), Kind::Boolean, -kInf, kInf, false, false, {}, "", std::move(doc), {}, {}};
  k.get = [sec, field](const Config& c) { return Value{c.*sec.*field}; };
  k.set = [sec, field](Config& c, const Value& v) { c.*sec.*field = std::get<bool>(v); };
  return k;
}
// A list of numbers, each in the range (an empty list allowed).
template <typename T>
KeySpec real_list(std::string key, T Config::*sec, std::vector<double> T::*field, double lo,
                  double hi, bool lo_open, std::string unit, std::string doc) {
  KeySpec k{std::move(key),  Kind::RealList, lo, hi, lo_open, false, {},
            std::move(unit), std::move(doc), {}, {}};
  k.get = [sec, field](const Config& c) { return Value{c.*sec.*field}; };
  k.set = [sec, field](Config& c, const Value& v) {
    c.*sec.*field = std::get<std::vector<double>>(v);
  };
  return k;
}
template <typename T>
KeySpec text(std::string key, T Config::*sec, std::string T::*field, std::string doc) {
  KeySpec k{std::move(key), Kind::Text, -kInf, kInf, false, false, {}, "", std::move(doc), {}, {}};
  k.get = [sec, field](const Config& c) { return Value{c.*sec.*field}; };
  k.set = [sec, field](Config& c, const Value& v) { c.*sec.*field = std::get<std::string>(v); };
  return k;
}
KeySpec choice(std::string key, std::vector<std::string> choices, std::string doc,
               std::function<Value(const Config&)> get,
               std::function<void(Config&, const Value&)> set) {
  return KeySpec{std::move(key), Kind::Choice,       -kInf, kInf,           false,
                 false,          std::move(choices), "",    std::move(doc), std::move(get),
                 std::move(set)};
}

// The keys a section declares itself (a pair law's XParams::declare), turned into schema rows.
template <typename T>
struct SectionKeys {
  std::vector<KeySpec>& rows;
  T Config::*section;
  void real(std::string key, double T::*field, double lo, double hi, bool lo_open, std::string unit,
            std::string doc, bool hi_open = false) {
    rows.push_back(sheardiff::real(std::move(key), section, field, lo, hi, lo_open, std::move(unit),
                                   std::move(doc), hi_open));
  }
  void integer(std::string key, std::int64_t T::*field, double lo, double hi, std::string unit,
               std::string doc) {
    rows.push_back(sheardiff::integer(std::move(key), section, field, lo, hi, std::move(unit),
                                      std::move(doc)));
  }
  void real_list(std::string key, std::vector<double> T::*field, double lo, double hi, bool lo_open,
                 std::string unit, std::string doc) {
    rows.push_back(sheardiff::real_list(std::move(key), section, field, lo, hi, lo_open,
                                        std::move(unit), std::move(doc)));
  }
  void boolean(std::string key, bool T::*field, std::string doc) {
    rows.push_back(sheardiff::boolean(std::move(key), section, field, std::move(doc)));
  }
  void choice(std::string key, std::vector<std::string> choices, std::string T::*field,
              std::string doc) {
    auto sec = section;
    rows.push_back(sheardiff::choice(
        std::move(key), std::move(choices), std::move(doc),
        [sec, field](const Config& c) { return Value{c.*sec.*field}; },
        [sec, field](Config& c, const Value& v) { c.*sec.*field = std::get<std::string>(v); }));
  }
};
template <typename T>
void declare_section(std::vector<KeySpec>& rows, T Config::*section) {
  SectionKeys<T> keys{rows, section};
  T::declare(keys);
}

const std::vector<KeySpec>& schema() {
  using C = Config;
  static const std::vector<KeySpec> specs = [] {
    std::vector<KeySpec> s;
    std::vector<std::string> scenes;
    std::string scene_doc = "Scene: ";
    for (const SceneKind& k : scene_registry()) {
      scene_doc += (scenes.empty() ? "" : "; ") + std::string(k.doc);
      scenes.push_back(k.name);
    }
    s.push_back(choice(
        "scene.type", scenes, scene_doc + ".", [](const C& c) { return Value{c.scene.type}; },
        [](C& c, const Value& v) { c.scene.type = std::get<std::string>(v); }));
    s.push_back(integer("scene.dimension", &C::scene, &C::Scene::dimension, 2, 3, "",
                        "2: discs in a monolayer of thickness flow.lz (the seed's set-up); 3: "
                        "spheres, periodic in z (docs/model.md, \"Three dimensions\"; the scenes "
                        "that have one: " +
                            scenes_of_spheres() + ")."));
    s.push_back(integer("particles.N", &C::particles, &C::ParticlesCfg::n, 2, 1e6, "",
                        "Number of mobile particles."));
    s.push_back(choice(
        "particles.mix", {"area", "volume", "number"},
        "How small (d) and large (size_ratio d) particles are mixed: equal total area, equal "
        "total volume (the default: the seed paper mixes its spheres in equal volume, N_small / "
        "N_large = size_ratio^3), or equal numbers.",
        [](const C& c) { return Value{std::string(to_string(c.particles.mix))}; },
        [](C& c, const Value& v) {
          const auto& t = std::get<std::string>(v);
          c.particles.mix = t == "area"     ? MixRule::Area
                            : t == "volume" ? MixRule::Volume
                                            : MixRule::Number;
        }));
    s.push_back(real("particles.size_ratio", &C::particles, &C::ParticlesCfg::size_ratio, 1.0, 3.0,
                     false, "", "Diameter of large particles over small ones."));
    s.push_back(real("particles.phi_init", &C::particles, &C::ParticlesCfg::phi_init, 0.0, 0.9,
                     true, "",
                     "Area fraction of the initial random placement (above ~0.55 it is reached "
                     "by compression with a soft repulsion)."));
    s.push_back(real("particles.aspect", &C::particles, &C::ParticlesCfg::aspect, 0.05, 20.0, false,
                     "",
                     "Initial cell height over width, Ly/Lx (spheres: the starting lattice's "
                     "height over its width, Lx = Lz)."));
    s.push_back(real("particles.phi_init_spheres", &C::particles,
                     &C::ParticlesCfg::phi_init_spheres, 0.0, 0.55, false, "",
                     "Spheres (scene.dimension = 3): volume fraction of the random start, reached "
                     "by compression with a soft repulsion; the pressure cell dilates or compacts "
                     "from it (0 = a loose lattice, volume fraction ~0.2, long to compact), simple "
                     "shear keeps it."));
    s.push_back(text("particles.init_file", &C::particles, &C::ParticlesCfg::init_file,
                     "Optional initial configuration: an H5MD file (`.h5`) or a plain table "
                     "`x y diameter`; empty = random placement. Relative paths are taken from "
                     "the config file's folder."));
    s.push_back(integer("particles.init_frame", &C::particles, &C::ParticlesCfg::init_frame, -1,
                        1e12, "", "Frame of an H5MD init_file to start from (-1 = last)."));
    // Below ~1e-10 the viscous forces (~J) are too small beside the contact springs for the
    // solve: at J = 1e-20 its residual check fails (measured, issue 16).
    s.push_back(real("flow.J", &C::flow, &C::Flow::j, 1e-10, 10.0, false, "1 (= gammadot eta/P)",
                     "Viscous number; in model units this is the shear rate gammadot."));
    s.push_back(real("flow.lz", &C::flow, &C::Flow::lz, 0.0, 100.0, true, "d",
                     "Thickness given to the monolayer for stresses and the wall load P Lx lz."));
    declare_section(s, &C::lubrication);
    declare_section(s, &C::contact);
    declare_section(s, &C::repulsion);
    s.push_back(choice(
        "integrator.type", {"implicit", "euler", "heun"},
        "Spring integration: `implicit` (linearly implicit springs, dt set by accuracy), "
        "`euler` or `heun` (explicit springs, dt capped by the contact stability limit).",
        [](const C& c) { return Value{std::string(to_string(c.integrator.type))}; },
        [](C& c, const Value& v) {
          const auto& t = std::get<std::string>(v);
          c.integrator.type = t == "implicit" ? IntegratorType::Implicit
                              : t == "euler"  ? IntegratorType::Euler
                                              : IntegratorType::Heun;
        }));
    s.push_back(real("integrator.dt", &C::integrator, &C::Integrator::dt, 0.0, 1e3, false, "eta/P",
                     "Fixed time step; 0 = adaptive (limits below)."));
    s.push_back(real("integrator.max_displacement", &C::integrator,
                     &C::Integrator::max_displacement, 0.0, 0.1, true, "d",
                     "Adaptive dt: largest non-affine displacement of any particle per step."));
    s.push_back(real("integrator.max_gap_fraction", &C::integrator,
                     &C::Integrator::max_gap_fraction, 0.0, 1.0, true, "",
                     "Adaptive dt: largest closing of any lubricated gap per step, as a fraction "
                     "of (gap + delta a_mean)."));
    s.push_back(real("integrator.max_overlap_change", &C::integrator,
                     &C::Integrator::max_overlap_change, 0.0, 0.1, false, "d",
                     "Adaptive dt: largest change of any contact overlap per step; 0 = "
                     "min(max_displacement, 10 d / ktilde), ten typical overlaps P d / kn."));
    s.push_back(real("integrator.max_entry_overlap", &C::integrator,
                     &C::Integrator::max_entry_overlap, 0.0, 0.1, false, "d",
                     "Adaptive dt: largest overlap a closing pair may reach in the step it "
                     "touches; 0 = off (the gap limit alone allows max_gap_fraction x delta "
                     "a_mean)."));
    s.push_back(real("integrator.max_strain_step", &C::integrator, &C::Integrator::max_strain_step,
                     0.0, 0.1, true, "1 (strain)", "Adaptive dt: upper bound gammadot dt."));
    s.push_back(real("integrator.explicit_safety", &C::integrator, &C::Integrator::explicit_safety,
                     0.0, 1.0, true, "",
                     "Explicit integrators: dt is at most this fraction of the contact "
                     "stability limit 2 R/k of the densest packing (docs/model.md section 7)."));
    s.push_back(choice(
        "solver.cholesky", {"cholmod", "eigen"},
        "Sparse Cholesky of the per-step system: `cholmod` (CHOLMOD supernodal, default: "
        "2.3x faster at N = 1000, docs/performance.md) or `eigen` (Eigen SimplicialLLT).",
        [](const C& c) { return Value{c.solver.cholesky}; },
        [](C& c, const Value& v) { c.solver.cholesky = std::get<std::string>(v); }));
    s.push_back(choice(
        "solver.rotations", {"auto", "always"},
        "Rotational unknowns: `auto` drops omega (2 unknowns per particle) when nothing couples "
        "rotation to translation (no friction and no tangential lubrication), `always` keeps 3.",
        [](const C& c) { return Value{c.solver.rotations}; },
        [](C& c, const Value& v) { c.solver.rotations = std::get<std::string>(v); }));
    s.push_back(real("neighbour.skin", &C::neighbour, &C::Neighbour::skin, 0.0, 5.0, true, "d",
                     "Verlet skin; the list is rebuilt when a particle has moved skin/2."));
    s.push_back(real("run.strain", &C::run, &C::Run::strain, 0.0, 1e5, true, "1",
                     "Total strain gammadot t to simulate."));
    s.push_back(integer("run.seed", &C::run, &C::Run::seed, 0, 9.0e18, "",
                        "Seed of the random initial placement."));
    s.push_back(integer("run.max_steps", &C::run, &C::Run::max_steps, 0, 9.0e18, "",
                        "Stop after this many steps even if run.strain is not reached (0 = no "
                        "limit)."));
    s.push_back(real("run.transient_strain", &C::run, &C::Run::transient_strain, 0.0, 1e5, false,
                     "1 (strain)",
                     "Strain after which time averages (summary.json) are accumulated."));
    s.push_back(real("walls.free_fall_speed", &C::walls, &C::Walls::free_fall_speed, 0.0, 100.0,
                     true, "P d / eta",
                     "pressure_shear: largest |V| of the top wall while (almost) nothing holds it, "
                     "so that it settles onto the packing instead of jumping."));
    s.push_back(real("walls.jitter", &C::walls, &C::Walls::jitter, 0.0, 1.0, false, "radius",
                     "pressure_shear: random y offset of wall particle centres (roughness)."));
    declare_section(s, &C::channel);
    declare_section(s, &C::steady);
    s.push_back(real("observables.wall_exclusion", &C::observables, &C::Observables::wall_exclusion,
                     0.0, 100.0, false, "d",
                     "pressure_shear: slab next to each wall left out of the bulk phi."));
    s.push_back(real("observables.profile_bin", &C::observables, &C::Observables::profile_bin, 0.0,
                     100.0, true, "d", "Bin width of the phi, u_x and T profiles across the gap."));
    s.push_back(boolean("observables.profiles", &C::observables, &C::Observables::profiles,
                        "Profiles across the gap of a scene with walls, over the measured window: "
                        "phi, u_x, T = <u'.u'> and the pair stresses sigma_xy and p per bin "
                        "(summary.json: profile_*). Off = they cost nothing."));
    declare_section(s, &C::analysis);
    s.push_back(real("output.frame_strain", &C::output, &C::Output::frame_strain, 0.0, 1e5, false,
                     "1 (strain)",
                     "Strain between two trajectory frames; 0 = 0.035 J^(1/4), i.e. 10 frames per "
                     "persistence time Psi gammadot = 0.35 J^(1/4) (seed eq. 3.6b)."));
    s.push_back(boolean("output.velocities", &C::output, &C::Output::velocities,
                        "Write velocities and angular velocities to the trajectory."));
    s.push_back(real("output.checkpoint_strain", &C::output, &C::Output::checkpoint_strain, 0.0,
                     1e5, false, "1 (strain)",
                     "Strain between two checkpoints (DIR/checkpoint.bin, written atomically at "
                     "a frame); 0 = only on SIGINT/SIGTERM. Resume with --resume DIR."));
    s.push_back(boolean("output.trajectory", &C::output, &C::Output::trajectory,
                        "Write DIR/trajectory.h5 (summary.json is always written)."));
    s.push_back(boolean("output.contacts", &C::output, &C::Output::contacts,
                        "Write the contact network of every frame to /connectivity/contacts of "
                        "the trajectory: pairs, normal and tangential force, sliding flag "
                        "(docs/trajectory.md)."));
    s.push_back(text("output.author", &C::output, &C::Output::author,
                     "Author's name in the trajectory (/h5md/author); empty: the environment "
                     "variable SHEARDIFF_AUTHOR, else the account's name."));
    s.push_back(real("health.max_overlap", &C::health, &C::Health::max_overlap, 0.0, 1.0, true, "d",
                     "Run health: stop the run (exit 4) when a contact overlaps by more. The "
                     "mean overlap is ~1/ktilde d, so 0.1 d is 10x it at ktilde = 1e2 and 1000x "
                     "at the default 1e4: only a broken step gets there (docs/stability.md)."));
    s.push_back(real("health.max_residual", &C::health, &C::Health::max_residual, 0.0, 1.0, true,
                     "1",
                     "Run health: stop the run (exit 4) when the relative residual of the force "
                     "balance solve, |A U - F| / |F|, exceeds this."));
    return s;
  }();
  return specs;
}

const KeySpec* find_spec(const std::string& key) {
  for (const auto& k : schema())
    if (k.key == key) return &k;
  return nullptr;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string suggestion(const std::string& key) {
  // A known name put in the wrong section: the same name elsewhere beats any spelling match.
  {
    const auto dot = key.find('.');
    const std::string name = dot == std::string::npos ? "." + key : key.substr(dot);
    std::vector<std::string> same;
    for (const auto& k : schema())
      if (k.key.size() > name.size() && k.key.ends_with(name) &&
          k.key.find('.') == k.key.size() - name.size())
        same.push_back("'" + k.key + "'");
    if (!same.empty()) {
      std::string list = same[0];
      for (std::size_t i = 1; i < same.size(); ++i) list += " or " + same[i];
      return fmt::format(" (did you mean {}?)", list);
    }
  }
  std::string best;
  std::size_t best_d = 4;
  for (const auto& k : schema()) {
    const std::size_t d = edit_distance(key, k.key);
    if (d < best_d) best_d = d, best = k.key;
  }
  return best.empty() ? "" : fmt::format(" (did you mean '{}'?)", best);
}

std::string range_text(const KeySpec& k) {
  switch (k.kind) {
    case Kind::Boolean:
      return "true or false";
    case Kind::Text:
      return "a string";
    case Kind::Choice: {
      std::string s = "one of";
      for (const auto& c : k.choices) s += " \"" + c + "\"";
      return s;
    }
    case Kind::Integer:
      return fmt::format("an integer in [{:g}, {:g}]", k.lo, k.hi);
    case Kind::Real:
      return fmt::format("a number in {}{:g}, {:g}{}", k.lo_open ? "(" : "[", k.lo, k.hi,
                         k.hi_open ? ")" : "]");
    case Kind::RealList:
      return fmt::format("a list of numbers in {}{:g}, {:g}{}", k.lo_open ? "(" : "[", k.lo, k.hi,
                         k.hi_open ? ")" : "]");
  }
  return "";
}

[[noreturn]] void fail(const std::string& origin, const std::string& key, const std::string& what) {
  throw ConfigError(fmt::format("{}: {}: {}", origin, key, what));
}

std::string describe(const toml::node& n) {
  std::ostringstream os;
  if (n.is_string()) os << '"' << *n.value<std::string>() << '"';
  // Shortest form that reads back exactly: -0.1, not -0.10000000000000001.
  else if (n.is_floating_point())
    os << toml_float(*n.value<double>());
  else if (n.is_table())
    os << "a table";
  else if (const auto* a = n.as_array()) {
    os << '[';
    for (std::size_t i = 0; i < a->size(); ++i) os << (i ? ", " : "") << describe(*a->get(i));
    os << ']';
  } else
    n.visit([&](const auto& v) { os << v; });
  return os.str();
}

Value convert(const toml::node& node, const KeySpec& k, const std::string& origin) {
  const auto bad = [&] {
    fail(origin, k.key,
         fmt::format("value {} is not allowed; expected {}", describe(node), range_text(k)));
  };
  Value v;
  switch (k.kind) {
    case Kind::Real:
      if (node.is_floating_point())
        v = *node.value<double>();
      else if (node.is_integer())
        v = static_cast<double>(*node.value<std::int64_t>());
      else
        bad();
      if (!std::isfinite(std::get<double>(v))) bad();
      break;
    case Kind::Integer:
      if (!node.is_integer()) bad();
      v = *node.value<std::int64_t>();
      break;
    case Kind::Boolean:
      if (!node.is_boolean()) bad();
      v = *node.value<bool>();
      break;
    case Kind::Text:
    case Kind::Choice:
      if (!node.is_string()) bad();
      v = *node.value<std::string>();
      break;
    case Kind::RealList: {
      const auto* list = node.as_array();
      if (!list) bad();
      std::vector<double> xs;
      for (const auto& item : *list) {
        if (!item.is_number()) bad();
        const double x = item.is_integer() ? static_cast<double>(*item.value<std::int64_t>())
                                           : *item.value<double>();
        if (!std::isfinite(x) || x < k.lo || x > k.hi || (k.lo_open && x == k.lo)) bad();
        xs.push_back(x);
      }
      v = xs;
      break;
    }
  }
  if (k.kind == Kind::Real || k.kind == Kind::Integer) {
    const double x =
        k.kind == Kind::Real ? std::get<double>(v) : static_cast<double>(std::get<std::int64_t>(v));
    if (x < k.lo || x > k.hi || (k.lo_open && x == k.lo) || (k.hi_open && x == k.hi)) bad();
  }
  if (k.kind == Kind::Choice &&
      std::find(k.choices.begin(), k.choices.end(), std::get<std::string>(v)) == k.choices.end())
    bad();
  return v;
}

void apply_table(Config& cfg, const toml::table& root, const std::string& origin) {
  for (const auto& [section, node] : root) {
    const std::string sec(section.str());
    const auto* table = node.as_table();
    if (!table) {
      fail(origin, sec,
           fmt::format("top-level keys are not allowed; expected a [section] table{}",
                       suggestion(sec)));
    }
    for (const auto& [name, value] : *table) {
      const std::string key = sec + "." + std::string(name.str());
      const KeySpec* spec = find_spec(key);
      if (!spec) fail(origin, key, "unknown key" + suggestion(key));
      spec->set(cfg, convert(value, *spec, origin));
    }
  }
}

// Spheres: a scene that has them, placed by its own builder.
void check_spheres(const Config& c, const std::string& origin) {
  if (c.scene.dimension != 3) return;
  if (!scene_kind(c.scene.type).spheres)
    fail(origin, "scene.dimension",
         fmt::format("3 (spheres) is allowed for scene.type = {}, not \"{}\"", scenes_of_spheres(),
                     c.scene.type));
  if (!c.particles.init_file.empty())
    fail(origin, "particles.init_file",
         "a scene of spheres (scene.dimension = 3) places its own spheres; leave it empty");
  if (scene_kind(c.scene.type).periodic_y && !(c.particles.phi_init_spheres > 0.0))
    fail(origin, "particles.phi_init_spheres",
         "a periodic cell of spheres is sheared at the volume fraction it starts at: allowed "
         "(0, 0.55]");
}

void check_combinations(const Config& c, const std::string& origin) {
  check_spheres(c, origin);
  if (const auto check = scene_kind(c.scene.type).check)
    if (const std::optional<ConfigProblem> problem = check(c))
      fail(origin, problem->key, problem->message);
  if (c.analysis.msd_window_lo >= c.analysis.msd_window_hi)
    fail(origin, "analysis.msd_window_lo",
         fmt::format("{:g} must be below analysis.msd_window_hi = {:g}", c.analysis.msd_window_lo,
                     c.analysis.msd_window_hi));
  if (c.particles.init_file.empty() && c.particles.phi_init > 0.86)
    fail(origin, "particles.phi_init",
         fmt::format("random placement with compression cannot reach {:g}; allowed up to 0.86 "
                     "without particles.init_file",
                     c.particles.phi_init));
  if (c.run.transient_strain >= c.run.strain)
    fail(origin, "run.transient_strain",
         fmt::format("{:g} must be smaller than run.strain = {:g}", c.run.transient_strain,
                     c.run.strain));
  if (c.output.frame_strain > c.run.strain)
    fail(origin, "output.frame_strain",
         fmt::format("{:g} is larger than run.strain = {:g}: no frame would be written",
                     c.output.frame_strain, c.run.strain));
  // A spacing far below the run's strain asks for more frames (or checkpoints, each a full
  // state on disk) than any disk holds, and one below the rounding of the strain never
  // advances: both are mistakes, refused with the smallest spacing allowed.
  const auto check_spacing = [&](const char* key, double spacing, const char* what) {
    if (spacing > 0.0 && c.run.strain / spacing > kMaxOutputsPerRun)
      fail(origin, key,
           fmt::format("{:g} asks for run.strain / {} = {:.3g} {}; at most {:g} are allowed, "
                       "i.e. {} >= {:g}",
                       spacing, key, c.run.strain / spacing, what, kMaxOutputsPerRun, key,
                       c.run.strain / kMaxOutputsPerRun));
  };
  check_spacing("output.frame_strain", c.output.frame_strain, "frames");
  check_spacing("output.checkpoint_strain", c.output.checkpoint_strain, "checkpoints");
}

// Whether the document or an override names `key` ("section.name").
bool names_key(const toml::table& root, const std::vector<std::string>& overrides,
               const std::string& key) {
  for (const auto& o : overrides)
    if (o.rfind(key + "=", 0) == 0) return true;
  const auto dot = key.find('.');
  return static_cast<bool>(root[key.substr(0, dot)][key.substr(dot + 1)]);
}

// The defaults of file_defaults() that apply to `c`, where the document and the overrides do not
// name their key.
void apply_file_defaults(Config& c, const toml::table& root,
                         const std::vector<std::string>& overrides) {
  for (const auto& d : file_defaults()) {
    if (!d.applies(c) || names_key(root, overrides, d.key)) continue;
    const KeySpec* spec = find_spec(d.key);
    if (!spec) throw std::logic_error("file_defaults(): no key " + d.key);
    spec->set(c, convert(*toml::parse("v = " + d.file_value).get("v"), *spec, "file default"));
  }
}

}  // namespace

const std::vector<FileDefault>& file_defaults() {
  // Spheres slide with the capped spring's stiffness across the stretch: at the sweep's step it
  // is the law closer to a 3x finer step, and it halves the low-J cost (docs/results-3d.md,
  // "The sliding law"). Runs of spheres before this default ran "none".
  static const std::vector<FileDefault> table{
      {"contact.sliding_stiffness", "spheres",
       [](const Config& c) { return c.scene.dimension == 3; }, "\"sideways\"", "\"none\""}};
  return table;
}

double overlap_change_limit(const Config& c) {
  if (c.integrator.max_overlap_change > 0.0) return c.integrator.max_overlap_change;
  // At ktilde <= 1e4 this is max_displacement (1e-3 d); stiffer contacts overlap less, and a
  // step that changes an overlap by many times its typical size P d / kn = d / ktilde
  // overshoots it (ktilde = 1e5, J = 1e-4, 1e-3 d: largest overlap 5x the converged one).
  return std::min(c.integrator.max_displacement, 10.0 / c.contact.ktilde);
}

void resolve_defaults(Config& c) {
  if (c.output.frame_strain <= 0.0)
    c.output.frame_strain = scene_kind(c.scene.type).default_frame_spacing
                                ? scene_kind(c.scene.type).default_frame_spacing(c)
                                : 0.035 * std::pow(c.flow.j, 0.25);
  if (c.analysis.sample_strain <= 0.0) c.analysis.sample_strain = 0.1 * c.output.frame_strain;
  if (c.analysis.coarse_strain <= 0.0)
    c.analysis.coarse_strain = std::min(0.2, c.analysis.msd_window_hi / 75.0);
}

Config parse_config(const std::string& toml_text, const std::string& origin,
                    const std::vector<std::string>& overrides, ConfigSource source) {
  Config cfg;
  toml::table root;
  try {
    root = toml::parse(toml_text, origin);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw ConfigError(
        fmt::format("{}:{}:{}: not valid TOML: {}", origin, b.line, b.column, e.description()));
  }
  apply_table(cfg, root, origin);
  for (const auto& o : overrides) {
    // TOML would read the text after a line break as further keys, silently set.
    if (o.find_first_of("\r\n") != std::string::npos)
      throw ConfigError(fmt::format(
          "--set {}: the value holds a line break; give one section.key=value per --set",
          o.substr(0, o.find_first_of("\r\n"))));
    const auto eq = o.find('=');
    const auto dot = o.find('.');
    if (eq == std::string::npos || dot == std::string::npos || dot > eq)
      throw ConfigError(
          fmt::format("--set {}: expected section.key=value (for example flow.J=1e-3)", o));
    const std::string key = o.substr(0, eq);
    const std::string val = o.substr(eq + 1);
    const KeySpec* spec = find_spec(key);
    if (!spec) fail("--set", key, "unknown key" + suggestion(key));
    toml::table t;
    try {
      t = toml::parse("v = " + val);
    } catch (const toml::parse_error&) {
      // Bare words are taken as strings so that --set integrator.type=heun works unquoted.
      try {
        t = toml::parse("v = \"" + val + "\"");
      } catch (const toml::parse_error&) {
        fail("--set", key, fmt::format("cannot read value '{}'", val));
      }
    }
    spec->set(cfg, convert(*t.get("v"), *spec, "--set"));
  }
  if (source == ConfigSource::file) apply_file_defaults(cfg, root, overrides);
  resolve_defaults(cfg);
  check_combinations(cfg, origin);
  return cfg;
}

Config load_config(const std::filesystem::path& file, const std::vector<std::string>& overrides,
                   ConfigSource source) {
  // A directory opens as an empty stream on Linux: it would run the defaults.
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec)
    throw ConfigError(
        fmt::format("{}: cannot open the config file: {}", file.string(), ec.message()));
  if (!std::filesystem::is_regular_file(status))
    throw ConfigError(fmt::format("{}: cannot open the config file: {}", file.string(),
                                  std::filesystem::is_directory(status)
                                      ? "it is a directory, not a TOML file"
                                      : "it is not a regular file"));
  std::ifstream in(file);
  if (!in)
    throw ConfigError(
        fmt::format("{}: cannot open the config file: {}", file.string(), std::strerror(errno)));
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad())
    throw ConfigError(
        fmt::format("{}: cannot read the config file: {}", file.string(), std::strerror(errno)));
  const std::string text = ss.str();
  Config cfg = parse_config(text, file.string(), overrides, source);
  // An empty or truncated file would otherwise run the default scene: the scene is the one
  // key a config file must give.
  if (!names_key(toml::parse(text), overrides, "scene.type")) {
    const auto& scenes = scene_registry();
    std::string others;
    for (std::size_t k = 0; k + 1 < scenes.size(); ++k)
      others += fmt::format("{}\"{}\"", others.empty() ? "" : ", ", scenes[k].name);
    fail(file.string(), "scene.type",
         fmt::format("missing: a config file must say which scene it runs, e.g. [scene] type = "
                     "\"{}\" (or {})",
                     scenes.back().name, others));
  }
  auto& init = cfg.particles.init_file;
  if (!init.empty() && std::filesystem::path(init).is_relative())
    init = (file.parent_path() / init).lexically_normal().string();
  return cfg;
}

namespace {

// A value as TOML: floats in their shortest round-trip form (0.7, not 0.69999999999999996;
// toml++'s own formatter writes 17 digits), strings quoted and escaped.
std::string toml_value(const Value& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::string>)
          return toml_string(x);
        else if constexpr (std::is_same_v<T, bool>)
          return x ? "true" : "false";
        else if constexpr (std::is_same_v<T, double>)
          return toml_float(x);
        else if constexpr (std::is_same_v<T, std::vector<double>>) {
          std::string out = "[";
          for (std::size_t i = 0; i < x.size(); ++i) out += (i ? ", " : "") + toml_float(x[i]);
          return out + "]";
        } else
          return fmt::format("{}", x);
      },
      v);
}

// A default for the reference: 0.7, 1e-06, 500, "uniform", true.
std::string default_text(const Value& v) {
  if (const double* x = std::get_if<double>(&v)) return fmt::format("{}", *x);
  return toml_value(v);
}

const char* type_name(Kind kind) {
  return kind == Kind::Real       ? "real"
         : kind == Kind::Integer  ? "integer"
         : kind == Kind::Boolean  ? "bool"
         : kind == Kind::RealList ? "list of reals"
                                  : "string";
}

std::pair<std::string, std::string> split_key(const std::string& key) {
  const auto dot = key.find('.');
  return {key.substr(0, dot), key.substr(dot + 1)};
}

}  // namespace

std::string to_toml(const Config& cfg) {
  std::map<std::string, std::string> sections;
  std::vector<std::string> order;
  for (const auto& k : schema()) {
    const auto [sec, name] = split_key(k.key);
    if (!sections.count(sec)) order.push_back(sec);
    sections[sec] += name + " = " + toml_value(k.get(cfg)) + "\n";
  }
  std::string out;
  for (const auto& sec : order) out += '[' + sec + "]\n" + sections[sec] + "\n";
  return out;
}

namespace {

// A config file's defaults for spheres, where the scene changes them (apply_file_defaults).
Config sphere_file_defaults() {
  Config c;
  c.scene.dimension = 3;
  apply_file_defaults(c, toml::table{}, {});
  return c;
}

// The default for the reference: one value, or the discs' and the spheres' where they differ.
std::string default_cell(const KeySpec& k, const Config& def, const Config& spheres) {
  const std::string discs = default_text(k.get(def)), balls = default_text(k.get(spheres));
  if (k.key == "scene.dimension" || discs == balls) return discs;
  return fmt::format("{} (discs), {} (spheres)", discs, balls);
}

}  // namespace

std::string config_reference_markdown() {
  std::ostringstream os;
  os << "| key | type | default | allowed | unit | meaning |\n|---|---|---|---|---|---|\n";
  const Config def, spheres = sphere_file_defaults();
  for (const auto& k : schema())
    os << "| `" << k.key << "` | " << type_name(k.kind) << " | " << default_cell(k, def, spheres)
       << " | " << range_text(k) << " | " << (k.unit.empty() ? "-" : k.unit) << " | " << k.doc
       << " |\n";
  return os.str();
}

std::string config_reference_text(std::size_t width) {
  std::string out = wrap_text(
      "sheardiff configuration: every key with its meaning, type, allowed values, unit and "
      "default, as a TOML file of the defaults (a config file must set scene.type; every other "
      "key is optional). Units: docs/units.md. The same as a Markdown table: sheardiff "
      "config-doc --markdown (docs/config.md).",
      width, "# ");
  const Config def, spheres = sphere_file_defaults();
  std::string section;
  for (const auto& k : schema()) {
    const auto [sec, name] = split_key(k.key);
    if (sec != section) {
      out += "\n[" + sec + "]\n";
      section = sec;
    }
    out += wrap_text(k.doc, width, "# ");
    out += wrap_text(
        fmt::format("allowed: {}{}", range_text(k), k.unit.empty() ? "" : "; unit: " + k.unit),
        width, "#   ");
    if (const std::string cell = default_cell(k, def, spheres); cell != default_text(k.get(def)))
      out += wrap_text("default: " + cell + "; the line below is the discs'", width, "#   ");
    out += name + " = " + toml_value(k.get(def)) + "\n";
  }
  return out;
}

}  // namespace sheardiff
