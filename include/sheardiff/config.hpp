#pragma once
// The run configuration: a TOML file validated against one schema (src/config.cpp), which is
// also the source of docs/config.md (`sheardiff config-doc`). Every key has a type, a range
// and a unit; unknown keys and out-of-range values are errors naming the file and the key.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "sheardiff/interactions/contact_params.hpp"
#include "sheardiff/interactions/lubrication_params.hpp"
#include "sheardiff/interactions/repulsion_params.hpp"
#include "sheardiff/observe/diffusion_params.hpp"
#include "sheardiff/observe/steady_state_params.hpp"
#include "sheardiff/scene/channel_params.hpp"

namespace sheardiff {

enum class IntegratorType { Implicit, Euler, Heun };
enum class MixRule { Area, Volume, Number };

// The first scene of the registry (src/scene/registry.cpp), the default scene.type.
std::string default_scene_name();

struct Config {
  struct Scene {
    std::string type = default_scene_name();
    std::int64_t dimension = 2;  // 2: discs in a monolayer; 3: spheres
  } scene;
  struct ParticlesCfg {
    std::int64_t n = 500;
    MixRule mix = MixRule::Volume;  // the seed (Appendix A): "mixed in equal volume"
    double size_ratio = 1.4;
    double phi_init = 0.7;
    double aspect = 1.0;             // Ly / Lx of the initial cell
    double phi_init_spheres = 0.45;  // volume fraction of a random start of spheres
    std::string init_file;
    std::int64_t init_frame = -1;
  } particles;
  struct Flow {
    double j = 1e-2;  // viscous number = gammadot in units P/eta
    double lz = 1.0;  // monolayer thickness for stresses and wall load
  } flow;
  // The pair laws' sections: each law declares its keys with its parameters.
  LubricationParams lubrication;
  ContactParams contact;
  RepulsionParams repulsion;
  struct Integrator {
    IntegratorType type = IntegratorType::Implicit;
    double dt = 0.0;  // 0 = adaptive
    double max_displacement = 1e-3;
    double max_gap_fraction = 0.5;
    double max_overlap_change = 0.0;  // 0 = overlap_change_limit(): from the contact stiffness
    double max_entry_overlap = 0.0;   // 0 = off: only the gap limit bounds a closing pair
    double max_strain_step = 1e-2;
    double explicit_safety = 0.5;
  } integrator;
  struct Solver {
    std::string cholesky = "cholmod";
    std::string rotations = "auto";  // "auto": no omega unknowns when nothing couples them
  } solver;
  struct Neighbour {
    double skin = 0.3;
  } neighbour;
  struct Run {
    double strain = 1.0;
    std::int64_t seed = 1;
    std::int64_t max_steps = 0;     // 0 = unlimited
    double transient_strain = 0.0;  // averages in summary.json start here
  } run;
  struct Walls {
    double free_fall_speed = 0.5;  // |V| cap while nothing holds the top wall
    double jitter = 0.4;           // y disorder of wall particle centres, in radii
  } walls;
  ChannelParams channel;     // the channel scene declares its keys
  SteadyStateParams steady;  // the pressure cell's steady-state test declares its keys
  struct Observables {
    double wall_exclusion = 3.0;  // d excluded next to each wall for the bulk phi
    double profile_bin = 0.5;     // d, bin width of the profiles across the gap
    bool profiles = true;         // profiles across the gap (scenes with walls)
  } observables;
  DiffusionParams analysis;  // the diffusion analysis declares its keys
  struct Output {
    double frame_strain = 0.0;  // 0 = resolved from J so that C(tau) gets >= 10 frames per Psi
    bool velocities = true;
    bool trajectory = true;
    double checkpoint_strain = 1.0;  // 0 = no periodic checkpoints
    bool contacts = false;           // the contact network of every frame in the trajectory
    std::string author;              // /h5md/author; empty: $SHEARDIFF_AUTHOR, else the account
  } output;
  struct Health {
    double max_overlap = 0.1;    // d: a run with a larger contact overlap is stopped
    double max_residual = 1e-6;  // relative residual of the force balance solve
  } health;
};

// Thrown for any invalid configuration; what() names the file, the key and the allowed range.
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Largest number of trajectory frames, and of checkpoints, one run may ask for
// (run.strain / output.frame_strain, run.strain / output.checkpoint_strain).
inline constexpr double kMaxOutputsPerRun = 1e7;

// Where a configuration's text comes from. `file`: a user's config file or a sweep's point, whose
// unnamed keys take today's defaults, some of which depend on the scene (a config file of spheres
// slides with contact.sliding_stiffness = "sideways"). `record`: what sheardiff wrote of a run
// (DIR/config.toml, checkpoint.bin, a stored sweep point); it names every key it knew, and a key
// it does not name was added since and takes the value that run ran with (Config's own default),
// so that a record reads as the run it was.
enum class ConfigSource { file, record };

// A default that a config file and a record resolve differently (ConfigSource): a file of the
// scenes where `applies` holds that does not name `key` takes `file_value`; a record that does
// not name it ran with `record_value`, Config's own default. Values as to_toml writes them
// ("\"none\"" for a string). `scenes` names those scenes in messages ("spheres").
struct FileDefault {
  std::string key, scenes;
  bool (*applies)(const Config&);
  std::string file_value, record_value;
};
// Every such default: the one table that parsing a file and the refusals over a changed default
// read (changed_default_hint).
const std::vector<FileDefault>& file_defaults();

// Parse a TOML document (origin names it in errors) and apply "section.key=value" overrides.
Config parse_config(const std::string& toml_text, const std::string& origin,
                    const std::vector<std::string>& overrides = {},
                    ConfigSource source = ConfigSource::file);
// A config file: parse_config, and further the file must be a regular file and must set
// scene.type (an empty file is not a run of the default scene).
Config load_config(const std::filesystem::path& file,
                   const std::vector<std::string>& overrides = {},
                   ConfigSource source = ConfigSource::file);
// Fills the defaults that depend on other keys (output.frame_strain = 0 -> from J). Done by
// parse_config; call it on a Config built in code.
void resolve_defaults(Config& cfg);
// The adaptive step's limit on the change of a contact overlap per step (d):
// integrator.max_overlap_change, or when it is 0, min(max_displacement, 10 d / ktilde), i.e.
// ten typical overlaps P d / kn (docs/performance.md, "Stiff contacts").
double overlap_change_limit(const Config& cfg);
// The resolved configuration as TOML (every key, defaults filled in; floats in the shortest
// text that parses back to the same double).
std::string to_toml(const Config& cfg);
// Markdown table of every key: name, type, default, allowed range, unit, meaning
// (`sheardiff config-doc --markdown`, docs/config.md).
std::string config_reference_markdown();
// The same for a terminal (`sheardiff config-doc`): a TOML file of the defaults, each key under
// its meaning, type, range and unit as comments, lines at most `width` columns (a longer line
// only where a single word is longer).
std::string config_reference_text(std::size_t width = 100);

const char* to_string(IntegratorType t);
const char* to_string(MixRule m);

}  // namespace sheardiff
