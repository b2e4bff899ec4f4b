// The scenario loader: YAML -> Scenario structs, collecting every problem it finds.
// Schema: src/scenario/SCHEMA.md.
#include "scenario/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>
#include <unordered_map>

#include "core/file_io.hpp"
#include "core/input_ranges.hpp"
#include "core/number_text.hpp"
#include "kinematics/machine.hpp"
#include "scenario/lifted_list.hpp"
#include "scenario/override_tree.hpp"
#include "scenario/overrides.hpp"
#include "scenario/schema.hpp"
#include "scenario/yaml_reader.hpp"
#include "toolpath/gcode.hpp"
#include "toolpath/hatching.hpp"
#include "toolpath/random_segments.hpp"
#include "toolpath/stl.hpp"

namespace depotwin {

namespace {

using namespace scenario_detail;
namespace fs = std::filesystem;

const std::vector<std::string> kToolpathKinds{"segments", "polylines", "gcode", "random_segments",
                                              "surface"};
// the paper's stage (Thompson & Yoon) when `limits:` is absent
constexpr double kDefaultVMax_mm_s = kDefaultTcpVMax_mm_s;
constexpr double kDefaultAMax_mm_s2 = kDefaultTcpAMax_mm_s2;
// a print speed may exceed an axis limit by this relative amount (rounding)
constexpr double kSpeedTolerance = 1e-9;
// the most grid points a surface toolpath may project, over all its layers
constexpr double kMaxSurfaceGridPoints = 2e7;
// print segments over speed listed before the rest are counted
constexpr std::size_t kMaxSpeedProblems = 20;
// an arc's directions, for the feed clamp, come from chords within this sagitta
constexpr double kClampChordTolerance_mm = 1e-3;
// the most points a G-code toolpath may take with its arcs cut into chords (2^26): a slicer's
// arc-fitted print of 10^6 arcs takes about 3 * 10^7
constexpr double kMaxImportedPoints = 67108864.0;
// a surface whose up-facing area is hidden under another part of it by more than this
// fraction is noted: the hatch leaves that area bare
constexpr double kHiddenAreaNoted = 0.01;
// a surface toolpath starts and ends this far above the part's highest point (and its layers)
constexpr double kSurfaceClearance_mm = 20.0;
// the longest `name:` or planner `label:` (each names a folder; file systems allow 255 bytes)
constexpr std::size_t kMaxFolderNameBytes = 100;
// the share of an angle's up-facing grid points standing alone (no line prints them) above
// which loading notes them
constexpr double kLonePointsNoted = 0.01;
// repeated print paths listed before the rest are counted
constexpr std::size_t kMaxRepeatProblems = 20;

// "" when `name` can name a results folder, else why not
std::string folder_name_problem(const std::string& name) {
  const std::string shown = "'" + printable_text(name) + "'";
  if (name.empty()) return "is empty: it names the results folder";
  if (name.size() > kMaxFolderNameBytes)
    return shown + " is " + std::to_string(name.size()) +
           " bytes long: it names a folder, at most " + std::to_string(kMaxFolderNameBytes);
  if (std::any_of(name.begin(), name.end(), [](char c) {
        const auto byte = static_cast<unsigned char>(c);
        return byte < 0x20 || byte == 0x7F;
      }))
    return shown +
           " holds a control character (newline, tab, escape, ...): it names a folder, so "
           "give printable text";
  if (name.find_first_not_of(' ') == std::string::npos)
    return shown + " is blank: it names the results folder";
  if (name.find_first_of("/\\") != std::string::npos || name == "." || name == "..")
    return shown + " cannot name a results folder (no '/', '\\', '.' or '..')";
  return "";
}

// true for a name a run's folder cannot take: one starting with '.' (hidden; the output
// folder's marker is .depotwin), or a file written beside the run folders (compare's
// comparison.*, a sweep task's task.json)
bool names_an_output_file(const std::string& label) {
  static const char* const kBesideRuns[] = {"comparison.json", "comparison.csv", "comparison.md",
                                            "comparison.png", "task.json"};
  return label.front() == '.' || std::any_of(std::begin(kBesideRuns), std::end(kBesideRuns),
                                             [&](const char* name) { return label == name; });
}

// "x -10 to 10, y -5 to 5, z 5": a box's extent per axis, one number where it is flat
std::string box_text(const Vec3& lower, const Vec3& upper) {
  std::string text;
  for (int axis = 0; axis < 3; ++axis) {
    text += std::string(axis > 0 ? ", " : "") + "xyz"[axis] + " " + format_number(lower[axis]);
    if (upper[axis] > lower[axis]) text += " to " + format_number(upper[axis]);
  }
  return text;
}

std::string join(const std::vector<std::string>& names, const std::string& separator = ", ") {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : separator) + name;
  return text;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string format_point(const Vec3& p) {
  return "(" + format_number(p.x()) + ", " + format_number(p.y()) + ", " + format_number(p.z()) +
         ")";
}

// a number with at most 4 significant digits, for speeds in messages
std::string format_speed(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

// the accepted range of a key in the schema's tables (scenario/schema.cpp)
const ValueRange& range_of(const std::string& section, const std::string& key) {
  return schema_section(section).key(key).range;
}

// the keys a section allows, from the same tables
std::vector<std::string> keys_of(const std::string& section) {
  return schema_section(section).key_names();
}

// a whole-number key's bounds
long long min_of(const std::string& section, const std::string& key) {
  return static_cast<long long>(range_of(section, key).min);
}
long long max_of(const std::string& section, const std::string& key) {
  return static_cast<long long>(range_of(section, key).max);
}

// where a print path came from, so its problems name the right file, line and key
struct PathOrigin {
  std::string file;
  std::string key;               // e.g. toolpath.segments[2]
  std::vector<int> point_lines;  // per point
  bool name_segments = true;     // false for a 2-point `segments` entry (the key says it all)
  // a hatch line's: its name ("layer 0, line 3") before each segment's, and its print speed's
  // key and line, where a speed above the limits is named (empty: the path's own)
  std::string path_name = {};
  std::string speed_key = {};
  int speed_line = 0;
};

class Loader {
 public:
  explicit Loader(const std::string& path) : problems_(path) {
    scenario_.file = path;
    const fs::path file_path(path);
    relative_dir_ = file_path.parent_path();
    std::error_code error;
    const fs::path absolute = fs::absolute(file_path, error);
    scenario_.directory =
        (error ? relative_dir_ : absolute.parent_path()).lexically_normal().string();
    scenario_.name = file_path.stem().string();
    scenario_.limits = MachineLimits::uniform(kDefaultVMax_mm_s, kDefaultAMax_mm_s2);
    scenario_.planners = {PlannerSpec{"lspb_mtt", {}, 0}, PlannerSpec{"stop_and_go", {}, 0}};
  }

  ScenarioReading read();
  // a sweep's task: the file's text given (not read), and overrides applied to its tree
  // before it is read (scenario/overrides.hpp)
  void set_source(const std::string* text, const std::vector<ScenarioOverride>* overrides) {
    text_ = text;
    overrides_ = overrides;
  }

 private:
  bool read_document(YAML::Node& root);
  void read_name(const Field& field);
  void read_machine(const Field& field);
  void read_machine_value(const Field& field);  // (read_machine less its bookkeeping)
  void read_limits(const Field& field);
  // false when v_max was given but unusable (speed checks on that axis are skipped)
  bool read_axis_limits(const MapView& view, const std::string& section, AxisLimits& axis);
  // the machine named, its joint limits applied, and its TCP limits per move
  void prepare_machine();
  void read_process(const Field& field);
  void read_toolpath(const Field* field);
  void read_segments(const Field& field, const std::optional<double>& default_speed);
  void read_polylines(const Field& field, const std::optional<double>& default_speed);
  void read_gcode_file(const Field& field, const std::optional<double>& default_speed,
                       bool start_given, bool end_given);
  // A problem when the paths would take more than kMaxImportedPoints points with their arcs
  // cut into chords within the file's chord_tolerance_mm (counted, none cut), naming the arc
  // that takes the most chords (its line kept in largest_arc_line_); else "".
  std::string chord_count_problem(const std::vector<PrintPath>& paths,
                                  const std::vector<std::vector<int>>& lines,
                                  const GcodeToolpath& settings);
  // the moves (distinct lines) among a path's points from `from` on
  static std::size_t distinct_moves(const std::vector<int>& point_lines, std::size_t from);
  // one problem when the imported paths lie at several z levels, at the first move off the
  // first level; false (nothing added) for a single level
  bool multi_level_problem(const GcodeImport& imported, const std::string& file,
                           const std::string& key);
  // `feed: clamp`: each edge slowed to what the limits allow along it, paths split where the
  // speed changes; counts and reports the moves slowed
  void clamp_feed_rates(std::vector<PrintPath>& paths, std::vector<std::vector<int>>& lines,
                        GcodeToolpath& settings);
  void read_random_segments(const Field& field, const std::optional<double>& default_speed,
                            bool start_given, bool end_given);
  void read_surface(const Field& field, const std::optional<double>& default_speed,
                    bool start_given, bool end_given);
  std::optional<std::vector<Vec3>> read_points(const Field& field, std::vector<int>& lines);
  void check_path(const PrintPath& path, const PathOrigin& origin);
  // a print path given twice (the same points, either way round) is refused: `paths` from
  // `first` on, as the file gives them under `key` (segments or polylines)
  void check_repeated_paths(std::size_t first, const std::string& kind);
  // cross-checks of settings read from different sections (sim against process)
  void check_settings();
  void read_arm(const Field& field);
  void read_order(const Field& field);
  bool read_order_name(const Field& field, OrderSpec& order);
  void read_planners(const Field& field);
  // the TCP limits over the toolpath's box (the machine's joint limits mapped), else the user's
  MachineLimits limits_in_force() const;
  void read_sim(const Field& field);
  void read_outputs(const Field& field);
  // a path as written, resolved against the scenario file's directory
  fs::path resolve(const std::string& given) const {
    return (relative_dir_ / given).lexically_normal();
  }

  ProblemList problems_;
  Scenario scenario_;
  fs::path relative_dir_;
  const std::string* text_ = nullptr;                         // given text, else the file's
  const std::vector<ScenarioOverride>* overrides_ = nullptr;  // applied to the tree
  // per TCP axis: its v_max is usable, so print speeds are checked against it
  std::array<bool, 3> axis_v_max_known_{true, true, true};
  bool joint_limits_bad_ = false;  // `limits.joint` given but unusable
  // `machine:` given without a known kinematics family: no machine's checks then (the
  // default machine's reach would only add errors about a machine the file does not name)
  bool machine_bad_ = false;
  // the machine named (when known) and its TCP limits per move, for the speed and reach checks
  std::unique_ptr<Machine> machine_;
  // where the nodes that aliases repeat begin (overrides may not edit them)
  std::vector<int> aliased_positions_;
  // a long segments list read without yaml-cpp (scenario/lifted_list.hpp)
  std::optional<LiftedSegments> lifted_;
  std::optional<TcpLimits> tcp_limits_;
  int largest_arc_line_ = 0;           // chord_count_problem's arc that takes the most chords
  std::size_t speed_problems_ = 0;     // print segments over speed, listed up to a count
  Problem last_listed_speed_problem_;  // where the "... and N more" line goes: after it
  int toolpath_speed_line_ = 0;        // toolpath.speed's line, 0 when not given
  bool speed_missing_ = false;         // reported once, not per path
};

ScenarioReading Loader::read() {
  ScenarioReading reading;
  YAML::Node root;
  if (!read_document(root)) {
    reading.problems = std::move(problems_.problems());
    reading.scenario = std::move(scenario_);
    return reading;
  }
  // a sweep task's overrides (an override the tree cannot take is a problem at its own line,
  // and the rest of the scenario is still read)
  if (overrides_ != nullptr)
    apply_overrides(root, *overrides_, problems_.problems(), aliased_positions_);

  // the top level: every key optional except the toolpath
  const MapView top(Field{root, "", 1, 1}, keys_of(""), problems_);
  reading.document_read = top.is_map();
  if (top.is_map()) {
    if (const Field* f = top.find("name")) read_name(*f);
    if (const Field* f = top.find("machine")) read_machine(*f);
    if (const Field* f = top.find("limits")) read_limits(*f);
    prepare_machine();
    if (const Field* f = top.find("process")) read_process(*f);
    read_toolpath(top.find("toolpath"));
    if (const Field* f = top.find("arm")) read_arm(*f);
    if (const Field* f = top.find("order")) read_order(*f);
    if (const Field* f = top.find("planners")) read_planners(*f);
    if (const Field* f = top.find("sim")) read_sim(*f);
    if (const Field* f = top.find("outputs")) read_outputs(*f);
    check_settings();
  }
  // `arm:` belongs to an arm
  if (scenario_.arm && !machine_bad_ && scenario_.machine != "arm6")
    problems_.add(scenario_.arm_line, "arm",
                  "applies to machine arm6 (a 6-DOF arm), not to " + scenario_.machine);
  if (speed_problems_ > kMaxSpeedProblems) {
    Problem more = last_listed_speed_problem_;
    more.message = "... and " + std::to_string(speed_problems_ - kMaxSpeedProblems) +
                   " more print segments above the speed limits (the first " +
                   std::to_string(kMaxSpeedProblems) + " are listed)";
    problems_.add_problem(std::move(more));
  }
  // what the machine makes of the paths that were read: every pose within its travel or
  // workspace (the arm's reach depends on the roll its posture chooses: prepare_job)
  // (the keys' lines first: the reach check names them)
  scenario_.key_lines = problems_.key_lines();
  // a G-code file's default end, above its start, out of the machine's reach (the top of a
  // delta's workspace is narrower than its bed): the file's last print point instead
  Toolpath& toolpath = scenario_.toolpath;
  if (machine_ && scenario_.gcode && scenario_.end_line <= 0 && !toolpath.paths.empty() &&
      toolpath.end_mm != toolpath.start_mm) {
    JointVector joints;
    if (!machine_->inverse(Pose(toolpath.end_mm), joints, nullptr)) {
      toolpath.end_mm = toolpath.paths.back().points.back();
      scenario_.exact_toolpath.end_mm = toolpath.end_mm;
    }
  }
  if (machine_ && scenario_.machine != "arm6")
    for (Problem& problem : unreachable_points(scenario_, *machine_))
      problems_.add_problem(std::move(problem));
  reading.problems = std::move(problems_.problems());
  // problems under an overridden key belong to the sweep file's override
  if (overrides_ != nullptr) attribute_to_overrides(reading.problems, *overrides_);
  sort_problems(reading.problems, problems_.file());
  reading.scenario = std::move(scenario_);
  return reading;
}

bool Loader::read_document(YAML::Node& root) {
  // the text given, else the file itself
  std::string text;
  if (text_ != nullptr) {
    text = *text_;
  } else {
    // a directory, a FIFO (reading it would wait for a writer) or nothing at all
    const std::string& file_path = problems_.file();
    std::string problem = missing_file_problem("scenario", "", file_path);
    if (problem.empty()) problem = settings_file_size_problem("scenario", file_path);
    if (!problem.empty()) {
      problems_.add(0, "", problem);
      return false;
    }
    std::ifstream in(file_path);
    std::stringstream buffer;
    buffer << in.rdbuf();
    if (!in) {
      problems_.add(0, "", "cannot read the scenario file");
      return false;
    }
    text = buffer.str();
  }
  // a long segments list is read apart (lifted_list.hpp), unless overrides may edit it in the
  // tree; then exactly one YAML document
  if (overrides_ == nullptr) lifted_ = lift_segments(text);
  std::optional<YAML::Node> document =
      parse_scenario_text(text, problems_, "scenario", &aliased_positions_);
  if (!document) return false;
  root = *document;
  return true;
}

void Loader::read_name(const Field& field) {
  const std::optional<std::string> name = read_string(field, problems_);
  if (!name) return;
  // it names the results folder: refused rather than changed, so the folder is the name
  const std::string problem = folder_name_problem(*name);
  if (!problem.empty()) {
    problems_.add(field.line, field.key, problem);
    return;
  }
  scenario_.name = *name;
}

void Loader::read_machine(const Field& field) {
  scenario_.machine_line = field.line;
  // (its kinematics family is what the checks need: a missing MJCF file still names one)
  machine_bad_ = true;
  read_machine_value(field);
}

void Loader::read_machine_value(const Field& field) {
  const std::string families = join(machine_names());
  // a registered machine by name
  if (field.node.IsScalar()) {
    const std::optional<std::string> machine = read_string(field, problems_);
    if (!machine) return;
    if (contains(machine_names(), *machine)) {
      scenario_.machine = *machine;
      machine_bad_ = false;
      return;
    }
    const bool mjcf = fs::path(*machine).extension() == ".xml";
    problems_.add(field.line, field.key,
                  mjcf ? "an MJCF file must name its kinematics family, which is never guessed: "
                         "machine: {model: " +
                             *machine + ", kinematics: NAME} with NAME one of " + families
                       : "unknown machine '" + *machine + "' (expected " + families +
                             ", or {model: FILE.xml, kinematics: NAME} for a model of your own)");
    return;
  }
  // an MJCF model of one's own, driven by a registered machine's kinematics
  const MapView view(field, {"model", "kinematics"}, problems_);
  if (!view.is_map()) return;
  for (const char* required : {"model", "kinematics"})
    if (!view.has(required))
      problems_.add(field.key_line, field.key,
                    std::string("missing ") + required +
                        " (an MJCF machine is {model: FILE.xml, kinematics: " + families + "})");
  if (const Field* f = view.find("kinematics")) {
    const std::optional<std::string> family = read_string(*f, problems_);
    if (family && !contains(machine_names(), *family))
      problems_.add(f->line, f->key,
                    "unknown kinematics family '" + *family + "' (expected " + families + ")");
    else if (family)
      scenario_.machine = *family, machine_bad_ = false;
  }
  if (const Field* f = view.find("model")) {
    const std::optional<std::string> model = read_string(*f, problems_);
    if (!model) return;
    const fs::path resolved = resolve(*model);
    std::error_code error;
    std::string problem;
    if (fs::path(*model).extension() != ".xml") {
      problems_.add(f->line, f->key, "'" + *model + "' is not an MJCF .xml file");
    } else if (!(problem = missing_file_problem("MJCF", *model, resolved.string())).empty()) {
      problems_.add(f->line, f->key, problem);
    } else {
      scenario_.model_path = fs::absolute(resolved, error).lexically_normal().string();
    }
  }
}

bool Loader::read_axis_limits(const MapView& view, const std::string& section, AxisLimits& axis) {
  bool v_max_ok = true;
  if (const Field* f = view.find("v_max")) {
    const std::optional<double> v_max = read_number(*f, problems_, range_of(section, "v_max"));
    v_max_ok = v_max.has_value();
    axis.v_max_mm_s = v_max.value_or(axis.v_max_mm_s);
  }
  if (const Field* f = view.find("a_max"))
    axis.a_max_mm_s2 =
        read_number(*f, problems_, range_of(section, "a_max")).value_or(axis.a_max_mm_s2);
  if (const Field* f = view.find("j_max")) {
    const std::optional<double> j_max = read_number(*f, problems_, range_of(section, "j_max"));
    // 0 is "no jerk limit"; a tiny one makes phases of 1e+300 s
    if (j_max && *j_max > 0.0 && *j_max < input_ranges::kMinLimit)
      problems_.add(f->line, f->key,
                    "must be 0 (no jerk limit) or at least " +
                        format_number(input_ranges::kMinLimit) + ", got " + format_number(*j_max));
    else if (j_max)
      axis.j_max_mm_s3 = *j_max;
  }
  return v_max_ok;
}

void Loader::read_limits(const Field& field) {
  const MapView view(field, keys_of("limits"), problems_);
  if (!view.is_map()) {
    axis_v_max_known_.fill(false);
    return;
  }
  // common values, then per-axis overrides; an axis whose v_max is unusable is left out of
  // the speed checks, the others are still checked
  AxisLimits common{kDefaultVMax_mm_s, kDefaultAMax_mm_s2, 0.0};
  const bool common_v_max_ok = read_axis_limits(view, "limits", common);
  static const char* kAxisNames[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    AxisLimits axis = common;
    bool v_max_ok = common_v_max_ok;
    if (const Field* f = view.find(kAxisNames[i])) {
      const MapView axis_view(*f, keys_of("limits.x"), problems_);
      if (axis_view.is_map()) {
        const bool own_v_max = axis_view.has("v_max");
        const bool read_ok = read_axis_limits(axis_view, "limits.x", axis);
        v_max_ok = own_v_max ? read_ok : common_v_max_ok;
      }
    }
    scenario_.limits.axes[i] = axis;
    axis_v_max_known_[i] = v_max_ok;
  }
  // joint (carriage) limits: no defaults, v_max and a_max are required
  if (const Field* f = view.find("joint")) {
    const MapView joint_view(*f, keys_of("limits.joint"), problems_);
    if (joint_view.is_map()) {
      const std::size_t problems_before = problems_.size();
      AxisLimits joint{0.0, 0.0, 0.0};
      for (const char* required : {"v_max", "a_max"})
        if (!joint_view.has(required))
          problems_.add(
              f->key_line, f->key,
              std::string("missing ") + required + " (joint limits need v_max and a_max)");
      read_axis_limits(joint_view, "limits.joint", joint);
      scenario_.joint_limits_line = f->key_line;
      // joint limits that did not read are not applied (the machine's own stay)
      if (problems_.size() == problems_before) {
        scenario_.has_joint_limits = true;
        scenario_.joint_limits = joint;
      } else {
        joint_limits_bad_ = true;
      }
    }
  }
  // the same rules the planners apply (MachineLimits::validate)
  const std::string problem = scenario_.limits.validate();
  if (!problem.empty()) {
    problems_.add(field.key_line, field.key, problem);
    axis_v_max_known_.fill(false);
  }
}

void Loader::prepare_machine() {
  if (machine_bad_) return;
  machine_ = make_machine(scenario_.machine);
  if (!machine_) return;
  // joint limits the machine cannot honour (e.g. a jerk limit on the delta's carriages)
  if (scenario_.has_joint_limits) {
    const std::string problem = machine_->set_joint_limits(scenario_.joint_limits);
    if (!problem.empty()) {
      problems_.add(scenario_.joint_limits_line, "limits.joint", problem);
      return;
    }
  }
  // the arm's limits depend on its posture (chosen after loading): the user's TCP limits here
  if (scenario_.machine == "arm6" || joint_limits_bad_) return;
  if (!scenario_.limits.validate().empty()) return;
  tcp_limits_ = machine_->tcp_limits(scenario_.limits);
}

void Loader::read_process(const Field& field) {
  const SchemaSection& section = schema_section("process");
  const MapView view(field, section.key_names(), problems_);
  if (!view.is_map()) return;
  ProcessSpec& process = scenario_.process;
  bool type_known = true;
  if (const Field* f = view.find("type")) {
    const std::vector<std::string>& types = section.key("type").choices;
    const std::optional<std::string> type = read_string(*f, problems_);
    type_known = type && contains(types, *type);
    if (type && !type_known)
      problems_.add(f->line, f->key,
                    "unknown process type '" + *type + "' (expected " + join(types, " or ") + ")");
    if (type_known) process.type = *type;
  }
  // a parameter of the other process type is a mistake, not something to ignore
  const auto read = [&](const std::string& key, double& target) {
    const Field* f = view.find(key);
    if (!f) return;
    const SchemaKey& declared = section.key(key);
    if (type_known && !declared.applies_to.empty() && declared.applies_to != process.type) {
      problems_.add(f->line, f->key,
                    "applies to " + declared.applies_to + ", not to process type " + process.type);
      return;
    }
    target = read_number(*f, problems_, declared.range).value_or(target);
  };
  read("flow_mm3_s", process.flow_mm3_s);
  read("sigma_mm", process.sigma_mm);
  read("line_width_mm", process.line_width_mm);
  read("shutter_time_s", process.shutter_time_s);
  read("bead_width_mm", process.bead_width_mm);
  read("layer_height_mm", process.layer_height_mm);
  read("tau_s", process.tau_s);
  if (const Field* f = view.find("retract")) {
    if (type_known && process.type != "extrusion")
      problems_.add(f->line, f->key, "applies to extrusion, not to process type " + process.type);
    else
      process.retract = read_bool(*f, problems_).value_or(process.retract);
  }
}

void Loader::read_toolpath(const Field* field) {
  if (!field) {
    problems_.add(1, "toolpath",
                  "missing: give the print paths, e.g. toolpath: {speed: 3, segments: [...]}");
    return;
  }
  const MapView view(*field, keys_of("toolpath"), problems_);
  if (!view.is_map()) return;
  Toolpath& toolpath = scenario_.toolpath;
  scenario_.toolpath_line = field->key_line;

  // default print speed, start and end (end defaults to start)
  std::optional<double> default_speed;
  if (const Field* f = view.find("speed")) {
    toolpath_speed_line_ = f->line;
    default_speed = read_number(*f, problems_, range_of("toolpath", "speed"));
    speed_missing_ = !default_speed;  // already reported: do not repeat per path
  }
  if (const Field* f = view.find("start")) {
    toolpath.start_mm = read_point(*f, problems_).value_or(Vec3::Zero());
    scenario_.start_line = f->line;
  }
  toolpath.end_mm = toolpath.start_mm;
  if (const Field* f = view.find("end")) {
    toolpath.end_mm = read_point(*f, problems_).value_or(toolpath.start_mm);
    scenario_.end_line = f->line;
  }

  // exactly one kind of print paths (segments, polylines, gcode, random_segments, surface)
  std::vector<const Field*> kinds;
  for (const std::string& kind : kToolpathKinds)
    if (const Field* f = view.find(kind)) kinds.push_back(f);
  std::stable_sort(kinds.begin(), kinds.end(),
                   [](const Field* a, const Field* b) { return a->key_line < b->key_line; });
  if (kinds.empty()) {
    problems_.add(
        field->key_line, field->key,
        "no print paths: give exactly one of segments, polylines, gcode, random_segments, "
        "surface");
    return;
  }
  for (std::size_t i = 1; i < kinds.size(); ++i)
    problems_.add(
        kinds[i]->line, kinds[i]->key,
        "a toolpath takes exactly one of segments, polylines, gcode, random_segments, surface; "
        "remove this or " +
            kinds.front()->key);
  const Field& kind = *kinds.front();
  const std::string name = kind.key.substr(kind.key.rfind('.') + 1);
  if (name == "segments") {
    read_segments(kind, default_speed);
  } else if (name == "polylines") {
    read_polylines(kind, default_speed);
  } else if (name == "gcode") {
    read_gcode_file(kind, default_speed, view.has("start"), view.has("end"));
  } else if (name == "random_segments") {
    read_random_segments(kind, default_speed, view.has("start"), view.has("end"));
  } else {
    read_surface(kind, default_speed, view.has("start"), view.has("end"));
  }

  // an offset moves everything (e.g. a G-code file or a random bed onto the machine); a part
  // is placed by its own surface.offset, which moves the part and its paths together
  if (const Field* f = view.find("offset"); f && name == "surface") {
    problems_.add(f->line, f->key,
                  "a surface toolpath is placed by surface.offset (and surface.rotation), which "
                  "move the part with its paths");
  } else if (f) {
    if (const std::optional<Vec3> offset = read_point(*f, problems_)) {
      for (Toolpath* moved : {&toolpath, &scenario_.exact_toolpath}) {
        moved->start_mm += *offset;
        moved->end_mm += *offset;
        for (PrintPath& path : moved->paths) {
          for (Vec3& point : path.points) point += *offset;
          for (EdgeArc& arc : path.arcs) arc.center_mm += *offset;
        }
      }
    }
  }
}

std::optional<std::vector<Vec3>> Loader::read_points(const Field& field, std::vector<int>& lines) {
  if (!expect_list(field, problems_, "a list of points [[x, y], ...]")) return std::nullopt;
  if (field.node.size() < 2) {
    problems_.add(field.line, field.key,
                  "a print path needs at least 2 points, got " + std::to_string(field.node.size()));
    return std::nullopt;
  }
  std::vector<Vec3> points;
  bool ok = true;
  for (std::size_t j = 0; j < field.node.size(); ++j) {
    const Field point_field = field.item(j);
    const std::optional<Vec3> point = read_point(point_field, problems_);
    ok = ok && point.has_value();
    points.push_back(point.value_or(Vec3::Zero()));
    lines.push_back(point_field.line);
  }
  if (!ok) return std::nullopt;
  return points;
}

void Loader::read_segments(const Field& field, const std::optional<double>& default_speed) {
  const std::size_t first_path = scenario_.toolpath.paths.size();
  // a list read apart: every entry already a valid pair of points, each on its own line
  if (lifted_ && lifted_->key_line == field.key_line) {
    if (!default_speed && !speed_missing_) {
      problems_.add(field.key_line, "toolpath.speed",
                    "missing: the print speed of the segments (mm/s)");
      speed_missing_ = true;
    }
    scenario_.toolpath.paths.reserve(lifted_->segments.size());
    scenario_.path_sources.reserve(lifted_->segments.size());
    for (std::size_t i = 0; i < lifted_->segments.size(); ++i) {
      PrintPath path;
      path.points = {lifted_->segments[i][0], lifted_->segments[i][1]};
      path.speed_mm_s = default_speed.value_or(0.0);
      path.source_index = static_cast<int>(i);
      const int line = lifted_->lines[i];
      check_path(
          path,
          PathOrigin{
              problems_.file(), field.key + "[" + std::to_string(i) + "]", {line, line}, false});
      scenario_.toolpath.paths.push_back(std::move(path));
    }
    check_repeated_paths(first_path, "segment");
    return;
  }
  if (!expect_list(field, problems_, "a list of segments [[x, y], [x, y]]")) return;
  if (field.node.size() == 0) {
    problems_.add(field.line, field.key, "is empty: give at least one segment");
    return;
  }
  if (!default_speed && !speed_missing_) {
    problems_.add(field.key_line, "toolpath.speed",
                  "missing: the print speed of the segments (mm/s)");
    speed_missing_ = true;
  }
  for (std::size_t i = 0; i < field.node.size(); ++i) {
    const Field item = field.item(i);
    if (!item.node.IsSequence() || item.node.size() != 2) {
      const std::string got = item.node.IsSequence()
                                  ? "a list of " + std::to_string(item.node.size()) + " points"
                                  : describe(item.node);
      problems_.add(item.line, item.key,
                    "expected a segment [[x, y], [x, y]] (two points), got " + got +
                        (item.node.IsSequence() ? " (use polylines for more)" : ""));
      continue;
    }
    std::vector<int> lines;
    const std::optional<std::vector<Vec3>> points = read_points(item, lines);
    if (!points) continue;
    PrintPath path;
    path.points = *points;
    path.speed_mm_s = default_speed.value_or(0.0);
    path.source_index = static_cast<int>(i);
    check_path(path, PathOrigin{problems_.file(), item.key, lines, false});
    scenario_.toolpath.paths.push_back(std::move(path));
  }
  check_repeated_paths(first_path, "segment");
}

void Loader::read_polylines(const Field& field, const std::optional<double>& default_speed) {
  const std::size_t first_path = scenario_.toolpath.paths.size();
  if (!expect_list(field, problems_, "a list of polylines")) return;
  if (field.node.size() == 0) {
    problems_.add(field.line, field.key, "is empty: give at least one polyline");
    return;
  }
  for (std::size_t i = 0; i < field.node.size(); ++i) {
    const Field item = field.item(i);
    // either a bare point list or {points: [...], speed: s}
    Field points_field = item;
    std::optional<double> speed = default_speed;
    bool speed_bad = false;
    if (item.node.IsMap()) {
      const MapView view(item, keys_of("toolpath.polylines[]"), problems_);
      const Field* points = view.find("points");
      if (const Field* f = view.find("speed")) {
        speed = read_number(*f, problems_, range_of("toolpath.polylines[]", "speed"));
        speed_bad = !speed;
      }
      if (!points) {
        problems_.add(item.line, item.key, "missing points: [[x, y], ...]");
        continue;
      }
      points_field = *points;
    } else if (!item.node.IsSequence()) {
      problems_.add(
          item.line, item.key,
          "expected a list of points or {points: [...], speed: s}, got " + describe(item.node));
      continue;
    }
    if (!speed && !speed_bad && !speed_missing_)
      problems_.add(item.line, item.key,
                    "no print speed: give toolpath.speed or speed: for this polyline");
    std::vector<int> lines;
    const std::optional<std::vector<Vec3>> points = read_points(points_field, lines);
    if (!points) continue;
    PrintPath path;
    path.points = *points;
    path.speed_mm_s = speed.value_or(0.0);
    path.source_index = static_cast<int>(i);
    check_path(path, PathOrigin{problems_.file(), item.key, lines, true});
    scenario_.toolpath.paths.push_back(std::move(path));
  }
  check_repeated_paths(first_path, "polyline");
}

void Loader::check_repeated_paths(std::size_t first, const std::string& kind) {
  // a hash of each path's points (in the direction that sorts first), then exact comparison
  // among equal hashes: linear in the number of points
  const std::vector<PrintPath>& paths = scenario_.toolpath.paths;
  const auto canonical_reversed = [](const PrintPath& path) {
    const std::vector<Vec3>& p = path.points;
    for (std::size_t i = 0, j = p.size() - 1; i < p.size(); ++i, --j) {
      for (int axis = 0; axis < 3; ++axis) {
        if (p[i][axis] != p[j][axis]) return p[j][axis] < p[i][axis];
      }
    }
    return false;
  };
  const auto point_at = [](const PrintPath& path, bool reversed, std::size_t k) -> const Vec3& {
    return reversed ? path.points[path.points.size() - 1 - k] : path.points[k];
  };
  const auto hash_of = [&](const PrintPath& path, bool reversed) {
    std::size_t hash = path.points.size();
    for (std::size_t k = 0; k < path.points.size(); ++k)
      for (int axis = 0; axis < 3; ++axis)
        hash = hash * 1000003u ^ std::hash<double>{}(point_at(path, reversed, k)[axis] + 0.0);
    return hash;
  };
  std::unordered_multimap<std::size_t, std::size_t> seen;  // hash -> index into paths
  std::size_t repeats = 0;
  // the last repeat listed: the "... and N more" line goes after it
  int last_repeat_line = scenario_.toolpath_line;
  std::string last_repeat_key = "toolpath";
  for (std::size_t i = first; i < paths.size(); ++i) {
    const PrintPath& path = paths[i];
    const bool reversed = canonical_reversed(path);
    const std::size_t hash = hash_of(path, reversed);
    const auto [begin, end] = seen.equal_range(hash);
    const auto same = std::find_if(begin, end, [&](const auto& entry) {
      const PrintPath& other = paths[entry.second];
      if (other.points.size() != path.points.size()) return false;
      const bool other_reversed = canonical_reversed(other);
      for (std::size_t k = 0; k < path.points.size(); ++k)
        if (point_at(other, other_reversed, k) != point_at(path, reversed, k)) return false;
      return true;
    });
    if (same == end) {
      seen.emplace(hash, i);
      continue;
    }
    if (++repeats > kMaxRepeatProblems) continue;
    const PathSource& source = scenario_.path_sources[static_cast<std::size_t>(path.source_index)];
    last_repeat_line = source.point_lines.empty() ? 0 : source.point_lines.front();
    last_repeat_key = source.key;
    const PathSource& earlier =
        scenario_.path_sources[static_cast<std::size_t>(paths[same->second].source_index)];
    problems_.add(
        source.point_lines.empty() ? 0 : source.point_lines.front(), source.key,
        "repeats " + earlier.key + " (the same points" +
            (path.points.front() == paths[same->second].points.front() ? "" : ", reversed") +
            "): every " + kind +
            " is printed once; for a thicker line raise process.flow_mm3_s or lower "
            "the speed");
  }
  if (repeats > kMaxRepeatProblems)
    problems_.add(last_repeat_line, last_repeat_key,
                  "... and " + std::to_string(repeats - kMaxRepeatProblems) + " more repeated " +
                      kind + "s (the first " + std::to_string(kMaxRepeatProblems) + " are listed)");
}

void Loader::read_gcode_file(const Field& field, const std::optional<double>& default_speed,
                             bool start_given, bool end_given) {
  // `gcode: FILE`, or `gcode: {file, rule, open, close, layers, feed, chord_tolerance_mm}`
  auto settings = std::make_shared<GcodeToolpath>();
  settings->line = field.key_line;
  const Field* file_field = &field;
  std::optional<MapView> view;
  if (field.node.IsMap()) {
    view.emplace(field, keys_of("toolpath.gcode"), problems_);
    file_field = view->find("file");
    if (!file_field) {
      problems_.add(field.line, field.key, "missing file: (the G-code file)");
      return;
    }
  }
  const std::optional<std::string> given = read_string(*file_field, problems_);
  if (!given) return;
  const fs::path resolved = resolve(*given);
  settings->file = resolved.string();
  GcodeOptions options;
  options.default_speed_mm_s = default_speed.value_or(0.0);
  bool bad_code = false;  // a shutter code that is none, or open and close that clash
  if (view) {
    const auto read_word = [&](const char* key, std::string& target) {
      const Field* f = view->find(key);
      if (!f) return;
      const std::optional<std::string> word = read_string(*f, problems_);
      if (!word) return;
      const std::vector<std::string>& choices = schema_section("toolpath.gcode").key(key).choices;
      if (!choices.empty() && !contains(choices, *word))
        problems_.add(f->line, f->key,
                      "unknown value '" + *word + "' (expected " + join(choices, " | ") + ")");
      else
        target = *word;
    };
    read_word("rule", settings->rule);
    read_word("open", settings->open_code);
    read_word("close", settings->close_code);
    // each a G or M code, and two different switches (else nothing can be read under them);
    // a problem of a code left at its default is named at the other code, which was given
    for (const ShutterCodeProblem& problem :
         shutter_code_problems(settings->open_code, settings->close_code)) {
      const Field* named = view->find(problem.at_close ? "close" : "open");
      const Field* f = named ? named : view->find(problem.at_close ? "open" : "close");
      problems_.add(f->line, f->key, problem.message);
      bad_code = true;
    }
    read_word("feed", settings->feed);
    if (const Field* f = view->find("chord_tolerance_mm"))
      settings->chord_tolerance_mm =
          read_number(*f, problems_, range_of("toolpath.gcode", "chord_tolerance_mm"))
              .value_or(settings->chord_tolerance_mm);
    if (const Field* f = view->find("layers")) {
      if (expect_list(*f, problems_, "[from, to]")) {
        if (f->node.size() != 2) {
          problems_.add(f->line, f->key,
                        "expected [from, to] (two layer indices), got " +
                            std::to_string(f->node.size()) + " values");
        } else {
          const auto from = read_integer(f->item(0), problems_, 0, 1000000000);
          const auto to = read_integer(f->item(1), problems_, 0, 1000000000);
          if (from && to && *from > *to)
            problems_.add(
                f->line, f->key,
                "from (" + std::to_string(*from) + ") is after to (" + std::to_string(*to) + ")");
          else if (from && to) {
            settings->first_layer = static_cast<int>(*from);
            settings->last_layer = static_cast<int>(*to);
          }
        }
      }
    }
  }
  options.rule = print_rule_from_name(settings->rule).value_or(PrintRule::automatic);
  options.open_code = settings->open_code;
  options.close_code = settings->close_code;
  options.first_layer = settings->first_layer;
  options.last_layer = settings->last_layer;
  scenario_.gcode = settings;
  if (bad_code) return;

  if (const std::string problem = missing_file_problem("G-code", *given, resolved.string());
      !problem.empty()) {
    problems_.add(file_field->line, file_field->key, problem);
    return;
  }
  GcodeImport imported;
  try {
    imported = read_gcode(resolved.string(), options);
  } catch (const InputError& e) {
    for (const Problem& p : e.problems()) {
      // a layer range the file does not have belongs to the scenario's `layers:`
      const Field* layers = view ? view->find("layers") : nullptr;
      if (layers && p.key == "toolpath.gcode.layers")
        problems_.add(layers->line, layers->key, p.message + " of '" + *given + "'");
      else
        problems_.add_problem(p);
    }
    return;
  }
  settings->rule_applied = print_rule_name(imported.rule);
  settings->rule_reason = imported.rule_reason;
  settings->layer_z_mm = imported.layer_z_mm;
  if (settings->rule == "auto")
    scenario_.notes.push_back("toolpath.gcode: " + imported.rule_reason);
  if (imported.first_speed_factor_line > 0)
    scenario_.notes.push_back(
        "toolpath.gcode: the M220 on line " + std::to_string(imported.first_speed_factor_line) +
        " sets a speed factor other than 100 %: " + std::to_string(imported.n_speed_factor_moves) +
        " moves run at their F times it, as firmware runs them");
  if (const std::string no_code = no_code_problem(imported.n_lines, imported.n_code_lines);
      !no_code.empty()) {
    problems_.add(field.line, field.key, "G-code file '" + *given + "' " + no_code);
    return;
  }
  if (imported.toolpath.paths.empty()) {
    problems_.add(
        field.line, field.key,
        "G-code file '" + *given + "' has no print moves under rule " + settings->rule_applied +
            (imported.rule_reason.empty() ? "" : " (" + imported.rule_reason + ")") +
            (settings->last_layer >= 0 ? " in layers [" + std::to_string(settings->first_layer) +
                                             ", " + std::to_string(settings->last_layer) + "]"
                                       : ""));
    return;
  }

  // a machine without a z axis cannot print several z levels: one problem, at the first move
  // that leaves the first level (never one per point)
  if (machine_ && !machine_->moves_tcp_z() &&
      multi_level_problem(imported, resolved.string(), field.key))
    return;

  // the paths as the file has them, arcs exact; a move counts once however it is cut later
  std::vector<PrintPath> exact_paths = imported.toolpath.paths;
  std::vector<std::vector<int>> exact_lines = imported.point_lines;
  for (const std::vector<int>& path_lines : exact_lines)
    settings->print_moves += static_cast<int>(distinct_moves(path_lines, 1));

  // the points the chords will take, counted before any is cut: an arc of absurd size (radius
  // 1e9 mm, within the numbers a file may hold) takes 10^6 chords, and a thousand of them
  // minutes to cut and check before each point is found out of reach
  if (const std::string too_many = chord_count_problem(exact_paths, exact_lines, *settings);
      !too_many.empty()) {
    problems_.add_problem(Problem{resolved.string(), largest_arc_line_, field.key, too_many});
    return;
  }

  // feed rates above what the machine can do along a move: slowed to it, as firmware does
  if (settings->feed == "clamp") clamp_feed_rates(exact_paths, exact_lines, *settings);

  // every path also with its arcs as chords within the tolerance (what planners that need
  // polylines get, and what the checks see); each chord point keeps the line of its move
  const bool keeps_arcs = std::any_of(exact_paths.begin(), exact_paths.end(),
                                      [](const PrintPath& path) { return path.has_arcs(); });
  const double tolerance_mm = settings->chord_tolerance_mm;
  for (std::size_t i = 0; i < exact_paths.size(); ++i) {
    PrintPath& exact = exact_paths[i];
    exact.source_index = static_cast<int>(scenario_.toolpath.paths.size());
    std::vector<std::size_t> source_point;
    PrintPath chorded = exact.chorded(tolerance_mm, &source_point);
    std::vector<int> chord_lines;
    for (std::size_t k : source_point) chord_lines.push_back(exact_lines[i].at(k));
    check_path(chorded, PathOrigin{resolved.string(), field.key, chord_lines, true});
    scenario_.toolpath.paths.push_back(std::move(chorded));
    if (keeps_arcs) scenario_.exact_toolpath.paths.push_back(std::move(exact));
  }

  // the start defaults to the file's first print point, the end to the start raised to the
  // file's highest print point (a file of several layers does not end by moving down through
  // them); `offset` then moves start, end and paths together
  Toolpath& toolpath = scenario_.toolpath;
  if (!start_given) toolpath.start_mm = toolpath.paths.front().points.front();
  if (!end_given) {
    toolpath.end_mm = toolpath.start_mm;
    for (const PrintPath& path : toolpath.paths)
      for (const Vec3& point : path.points)
        toolpath.end_mm.z() = std::max(toolpath.end_mm.z(), point.z());
  }
  scenario_.exact_toolpath.start_mm = toolpath.start_mm;
  scenario_.exact_toolpath.end_mm = toolpath.end_mm;
  scenario_.exact_toolpath.chord_tolerance_mm = tolerance_mm;
}

std::string Loader::chord_count_problem(const std::vector<PrintPath>& paths,
                                        const std::vector<std::vector<int>>& lines,
                                        const GcodeToolpath& settings) {
  double points = 0.0, largest = 0.0, largest_radius_mm = 0.0;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const PrintPath& path = paths[i];
    points += static_cast<double>(path.points.size());
    for (std::size_t k = 0; k < path.arcs.size(); ++k) {
      const EdgeArc& arc = path.arcs[k];
      if (!arc.is_arc()) continue;
      const Vec3 radial = path.points[k] - arc.center_mm;
      const double radius_mm = (radial - radial.dot(arc.axis) * arc.axis).norm();
      const double chords = arc_chord_count(radius_mm, arc.sweep_rad, settings.chord_tolerance_mm);
      points += chords - 1.0;
      if (chords > largest) {
        largest = chords;
        largest_radius_mm = radius_mm;
        largest_arc_line_ = lines[i].at(k + 1);
      }
    }
  }
  if (points <= kMaxImportedPoints) return "";
  std::ostringstream message;
  const auto whole = [](double count) { return std::to_string(static_cast<long long>(count)); };
  message << "the print moves take " << whole(points)
          << " points with their arcs cut into chords within chord_tolerance_mm "
          << format_number(settings.chord_tolerance_mm) << " mm, more than a job holds ("
          << whole(kMaxImportedPoints) << "); the arc on this line alone takes " << whole(largest)
          << " (radius " << format_number(largest_radius_mm)
          << " mm): check its I, J, K or R, or raise chord_tolerance_mm";
  return message.str();
}

std::size_t Loader::distinct_moves(const std::vector<int>& point_lines, std::size_t from) {
  // a move is a line of the file; the chords of an arc share their move's line
  std::size_t count = 0;
  int previous = -1;
  for (std::size_t k = from; k < point_lines.size(); ++k) {
    if (point_lines[k] != previous) ++count;
    previous = point_lines[k];
  }
  return count;
}

bool Loader::multi_level_problem(const GcodeImport& imported, const std::string& file,
                                 const std::string& key) {
  // the first move, in the file's order, that leaves the first print point's z: within a print
  // run (a plunge or ramp with the shutter open: no layer choice helps) or at a run of its own
  // at another height (a layer)
  const std::vector<PrintPath>& paths = imported.toolpath.paths;
  const double first_z_mm = paths.front().points.front().z();
  const auto off_level = [](double a_mm, double b_mm) { return std::abs(a_mm - b_mm) > 1e-6; };
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const std::vector<Vec3>& points = paths[i].points;
    const double run_z_mm = points.front().z();
    for (std::size_t k = 1; k < points.size(); ++k) {
      if (!off_level(points[k].z(), run_z_mm)) continue;
      problems_.add_problem(Problem{
          file, imported.point_lines[i].at(k), key,
          "this print move changes z from " + format_number(run_z_mm) + " to " +
              format_number(points[k].z()) + " mm while printing (a plunge or ramp with the " +
              "shutter open or the material flowing) but " + scenario_.machine +
              " has no z axis (start printing at the working height, or use a machine with z " +
              "such as cartesian)"});
      return true;
    }
    if (!off_level(run_z_mm, first_z_mm)) continue;
    // a layer at another height: how many heights the file's runs print at
    std::vector<double> levels;
    for (const PrintPath& path : paths) {
      const double z_mm = path.points.front().z();
      if (std::none_of(levels.begin(), levels.end(),
                       [&](double level) { return !off_level(level, z_mm); }))
        levels.push_back(z_mm);
    }
    std::sort(levels.begin(), levels.end());
    problems_.add_problem(Problem{
        file, imported.point_lines[i].front(), key,
        "the file prints at " + std::to_string(levels.size()) + " z levels (" +
            format_number(levels.front()) + " to " + format_number(levels.back()) + " mm) but " +
            scenario_.machine + " has no z axis: this move leaves z = " +
            format_number(first_z_mm) + " mm for z = " + format_number(run_z_mm) +
            " mm (select one layer with gcode: {file: ..., layers: [k, k]}, or use a machine "
            "with z such as cartesian)"});
    return true;
  }
  return false;
}

void Loader::clamp_feed_rates(std::vector<PrintPath>& paths, std::vector<std::vector<int>>& lines,
                              GcodeToolpath& settings) {
  std::vector<PrintPath> clamped_paths;
  std::vector<std::vector<int>> clamped_lines;
  double largest_cut = 1.0, from_mm_s = 0.0, to_mm_s = 0.0;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const PrintPath& path = paths[i];
    const std::vector<int>& path_lines = lines[i];
    // each edge's speed: the path's, or the most every axis allows along it (the user's
    // limits, with the machine's joint limits mapped over the edge)
    std::vector<double> edge_speed(path.points.size() - 1, path.speed_mm_s);
    int last_clamped_line = -1;
    for (std::size_t k = 0; k + 1 < path.points.size() && path.speed_mm_s > 0.0; ++k) {
      // the edge's directions: the line's, or an arc's as fine chords of it and as the
      // chords the checks and the polyline planners get (chord_tolerance_mm), whose
      // directions differ: a coarse chord across an arc's top runs along the axis
      std::vector<std::vector<Vec3>> edge_chords{{path.points[k], path.points[k + 1]}};
      if (!path.arcs.empty() && path.arcs[k].is_arc()) {
        PrintPath arc_edge;
        arc_edge.points = edge_chords.front();
        arc_edge.arcs = {path.arcs[k]};
        edge_chords = {arc_edge.chorded(kClampChordTolerance_mm).points,
                       arc_edge.chorded(settings.chord_tolerance_mm).points};
      }
      double allowed_mm_s = path.speed_mm_s;
      // an arc's exact tangents, over each fine chord's part of it: a planner may cut the arc
      // into other chords, whose directions lie between these tangents (the fine chords' own
      // miss the axis-aligned tangent at an arc's extreme by half a chord's turn, 1.8 degrees
      // at radius 2 mm, which allowed 20.01 mm/s where v_max was 20)
      if (!path.arcs.empty() && path.arcs[k].is_arc()) {
        const std::size_t fine_chords = edge_chords.front().size() - 1;
        const double sweep_rad = path.arcs[k].sweep_rad;
        for (std::size_t c = 0; c < fine_chords; ++c) {
          const double s0 = static_cast<double>(c) / fine_chords;
          const double s1 = static_cast<double>(c + 1) / fine_chords;
          const MachineLimits limits =
              tcp_limits_ ? tcp_limits_->along(edge_chords.front()[c], edge_chords.front()[c + 1])
                          : scenario_.limits;
          const Vec3 extent = arc_tangent_extent(path.points[k], path.points[k + 1], path.arcs[k],
                                                 s0 * sweep_rad, s1 * sweep_rad);
          for (int axis = 0; axis < 3; ++axis)
            if (axis_v_max_known_[axis] && extent[axis] > 0.0)
              allowed_mm_s = std::min(allowed_mm_s, limits.axes[axis].v_max_mm_s / extent[axis]);
        }
      }
      for (const std::vector<Vec3>& edge_points : edge_chords)
        for (std::size_t c = 0; c + 1 < edge_points.size(); ++c) {
          const Vec3 step = edge_points[c + 1] - edge_points[c];
          const double length_mm = step.norm();
          if (length_mm <= kJoinTolerance_mm) continue;
          const MachineLimits limits = tcp_limits_
                                           ? tcp_limits_->along(edge_points[c], edge_points[c + 1])
                                           : scenario_.limits;
          for (int axis = 0; axis < 3; ++axis)
            if (axis_v_max_known_[axis] && std::abs(step[axis]) > 0.0)
              allowed_mm_s = std::min(
                  allowed_mm_s, limits.axes[axis].v_max_mm_s * length_mm / std::abs(step[axis]));
        }
      if (allowed_mm_s >= path.speed_mm_s) continue;
      edge_speed[k] = allowed_mm_s;
      // a move (a line of the file) counts once, however many chords it has
      if (path_lines.at(k + 1) != last_clamped_line) ++settings.clamped_moves;
      last_clamped_line = path_lines.at(k + 1);
      if (allowed_mm_s / path.speed_mm_s < largest_cut) {
        largest_cut = allowed_mm_s / path.speed_mm_s;
        from_mm_s = path.speed_mm_s;
        to_mm_s = allowed_mm_s;
      }
    }
    // runs of edges at one speed become paths (a speed change starts a new path at the same
    // point, as the importer does for a change of F)
    std::size_t run_start = 0;
    for (std::size_t k = 1; k <= edge_speed.size(); ++k) {
      if (k < edge_speed.size() && edge_speed[k] == edge_speed[run_start]) continue;
      // (the path's fields, its per-point lists cut to the run: a copy of the whole path per
      // run made a serpentine of 3e6 clamped moves quadratic in memory, 21 GB)
      PrintPath piece;
      piece.source_index = path.source_index;
      piece.layer = path.layer;
      piece.points.assign(path.points.begin() + static_cast<long>(run_start),
                          path.points.begin() + static_cast<long>(k) + 1);
      if (!path.normals.empty())
        piece.normals.assign(path.normals.begin() + static_cast<long>(run_start),
                             path.normals.begin() + static_cast<long>(k) + 1);
      if (!path.rolls.empty())
        piece.rolls.assign(path.rolls.begin() + static_cast<long>(run_start),
                           path.rolls.begin() + static_cast<long>(k) + 1);
      if (!path.arcs.empty())
        piece.arcs.assign(path.arcs.begin() + static_cast<long>(run_start),
                          path.arcs.begin() + static_cast<long>(k));
      piece.speed_mm_s = edge_speed[run_start];
      clamped_paths.push_back(std::move(piece));
      clamped_lines.emplace_back(path_lines.begin() + static_cast<long>(run_start),
                                 path_lines.begin() + static_cast<long>(k) + 1);
      run_start = k;
    }
  }
  paths = std::move(clamped_paths);
  lines = std::move(clamped_lines);
  if (settings.clamped_moves > 0)
    scenario_.notes.push_back(
        "toolpath.gcode: " + std::to_string(settings.clamped_moves) + " of " +
        std::to_string(settings.print_moves) +
        " print moves asked for more than the machine's speed limits and were slowed to them "
        "(feed: clamp, as firmware does; the largest cut " +
        format_speed(from_mm_s) + " -> " + format_speed(to_mm_s) + " mm/s)");
}

void Loader::read_random_segments(const Field& field, const std::optional<double>& default_speed,
                                  bool start_given, bool end_given) {
  const std::size_t problems_before = problems_.size();
  const std::string section = "toolpath.random_segments";
  const MapView view(field, keys_of(section), problems_);
  if (!view.is_map()) return;
  RandomSegmentsSpec spec;
  if (const Field* f = view.find("n"))
    spec.count =
        static_cast<int>(read_integer(*f, problems_, min_of(section, "n"), max_of(section, "n"))
                             .value_or(spec.count));
  const Range size_range{0.0, false, input_ranges::kMaxCoordinate_mm, true};
  if (const Field* f = view.find("bed")) {
    if (const auto bed = read_numbers(*f, problems_, 2, size_range)) {
      spec.bed_x_mm = (*bed)[0];
      spec.bed_y_mm = (*bed)[1];
    }
  }
  if (const Field* f = view.find("length")) {
    if (const auto length = read_numbers(*f, problems_, 2, size_range)) {
      if ((*length)[0] > (*length)[1])
        problems_.add(f->line, f->key,
                      "expected [min, max] with min <= max, got [" + format_number((*length)[0]) +
                          ", " + format_number((*length)[1]) + "]");
      spec.length_min_mm = (*length)[0];
      spec.length_max_mm = (*length)[1];
    }
  }
  // the bed and the lengths make the instance: required, as the schema says (they were
  // defaulted silently to a 100 x 100 bed)
  if (!view.find("bed"))
    problems_.add(field.key_line, section + ".bed",
                  "missing: the bed's size [w, h] in mm, inside which the segments lie");
  if (!view.find("length"))
    problems_.add(field.key_line, section + ".length",
                  "missing: the segments' lengths [min, max] in mm");
  if (const Field* f = view.find("seed")) spec.seed = read_seed(*f, problems_).value_or(spec.seed);
  std::optional<double> speed = default_speed;
  bool speed_bad = false;
  if (const Field* f = view.find("speed")) {
    speed = read_number(*f, problems_, range_of(section, "speed"));
    speed_bad = !speed;
  }
  if (!speed && !speed_bad && !speed_missing_)
    problems_.add(field.key_line, field.key, "no print speed: give toolpath.speed or speed: here");
  if (problems_.size() != problems_before || !speed) return;
  spec.speed_mm_s = *speed;

  // generate; the generator's own problems get this file and line
  Toolpath generated;
  try {
    generated = make_random_segments(spec);
  } catch (const InputError& e) {
    for (Problem p : e.problems()) {
      if (p.file.empty()) {
        p.file = problems_.file();
        p.line = field.key_line;
      }
      if (p.key.empty()) p.key = field.key;
      problems_.add_problem(p);
    }
    return;
  }
  // the instance's start and end apply where the file gives none (end defaults to start)
  Toolpath& toolpath = scenario_.toolpath;
  if (!start_given) toolpath.start_mm = generated.start_mm;
  if (!end_given) toolpath.end_mm = start_given ? toolpath.start_mm : generated.end_mm;
  for (PrintPath& path : generated.paths) {
    check_path(path, PathOrigin{problems_.file(), field.key,
                                std::vector<int>(path.points.size(), field.key_line), true});
    scenario_.toolpath.paths.push_back(std::move(path));
  }
}

void Loader::read_surface(const Field& field, const std::optional<double>& default_speed,
                          bool start_given, bool end_given) {
  const std::size_t problems_before = problems_.size();
  const std::string section = "toolpath.surface";
  const MapView view(field, keys_of(section), problems_);
  if (!view.is_map()) return;
  auto surface = std::make_shared<SurfaceToolpath>();
  surface->line = field.key_line;

  // the part: its STL file, units and placement
  std::string given_file;
  if (const Field* f = view.find("file")) {
    if (const std::optional<std::string> file = read_string(*f, problems_)) {
      given_file = *file;
      const fs::path resolved = resolve(*file);
      const std::string problem = missing_file_problem("STL", *file, resolved.string());
      if (!problem.empty())
        problems_.add(f->line, f->key, problem);
      else
        surface->file = resolved.string();
    }
  } else {
    problems_.add(field.key_line, field.key, "missing file: the STL of the part's top surface");
  }
  if (const Field* f = view.find("units")) {
    const std::optional<std::string> units = read_string(*f, problems_);
    // (a CAD program's export in metres is common: 0.04 read as mm is no part at all)
    if (units && *units == "mm")
      surface->mm_per_unit = 1.0;
    else if (units && *units == "cm")
      surface->mm_per_unit = 10.0;
    else if (units && *units == "m")
      surface->mm_per_unit = 1000.0;
    else if (units && (*units == "inch" || *units == "in"))
      surface->mm_per_unit = 25.4;
    else if (units)
      problems_.add(f->line, f->key, "unknown units '" + *units + "' (expected mm, cm, m or inch)");
  }
  if (const Field* f = view.find("offset"))
    surface->offset_mm = read_point(*f, problems_).value_or(Vec3::Zero());
  if (const Field* f = view.find("rotation")) {
    const Range turn = Range::closed(-360.0, 360.0);
    if (f->node.IsScalar()) {
      surface->rotation_deg.z() = read_number(*f, problems_, turn).value_or(0.0);
    } else if (const auto angles = read_numbers(*f, problems_, 3, turn)) {
      surface->rotation_deg = Vec3((*angles)[0], (*angles)[1], (*angles)[2]);
    }
  }

  // the hatch (Algorithm 1)
  if (const Field* f = view.find("hatch_mm"))
    surface->hatch_mm =
        read_number(*f, problems_, range_of(section, "hatch_mm")).value_or(surface->hatch_mm);
  if (const Field* f = view.find("angles")) {
    if (expect_list(*f, problems_, "a list of hatch angles in degrees, e.g. [0, 90]")) {
      if (f->node.size() == 0) problems_.add(f->line, f->key, "is empty: give at least one angle");
      std::vector<double> angles;
      for (std::size_t i = 0; i < f->node.size(); ++i)
        if (const std::optional<double> angle =
                read_number(f->item(i), problems_, Range::closed(-360.0, 360.0)))
          angles.push_back(*angle);
      if (!angles.empty()) surface->angles_deg = angles;
    }
  }
  if (const Field* f = view.find("layers"))
    surface->layers = static_cast<int>(
        read_integer(*f, problems_, min_of(section, "layers"), max_of(section, "layers"))
            .value_or(surface->layers));
  if (const Field* f = view.find("layer_height_mm"))
    surface->layer_height_mm = read_number(*f, problems_, range_of(section, "layer_height_mm"))
                                   .value_or(surface->layer_height_mm);
  if (const Field* f = view.find("alpha"))
    surface->alpha =
        read_number(*f, problems_, range_of(section, "alpha")).value_or(surface->alpha);
  if (const Field* f = view.find("layer_offset")) {
    const std::optional<std::string> mode = read_string(*f, problems_);
    if (mode && (*mode == "normal" || *mode == "z"))
      surface->layer_offset = *mode;
    else if (mode)
      problems_.add(f->line, f->key,
                    "unknown layer offset '" + *mode +
                        "' (expected normal: along the surface normal, or z: vertical, as in "
                        "the paper)");
  }
  if (const Field* f = view.find("chord_tolerance_mm")) {
    surface->chord_tolerance_mm =
        read_number(*f, problems_, range_of(section, "chord_tolerance_mm"))
            .value_or(surface->chord_tolerance_mm);
    // (a tolerance of atoms refines every chord of a curved surface to its limit and cuts each
    // crease's arc into millions of chords: gigabytes, then out of memory)
    if (surface->chord_tolerance_mm > 0.0 &&
        surface->chord_tolerance_mm < SurfaceHatchSpec::kLeastChordTolerance_mm)
      problems_.add(f->line, f->key,
                    "is " + format_number(surface->chord_tolerance_mm) + " mm: give 0 (the " +
                        "grid's points only) or at least " +
                        format_number(SurfaceHatchSpec::kLeastChordTolerance_mm) + " mm");
  }
  std::optional<double> speed = default_speed;
  // where the hatch's speed is given, for the segments it is too fast on
  std::string speed_key = "toolpath.speed";
  int speed_line = toolpath_speed_line_;
  if (const Field* f = view.find("speed")) {
    speed = read_number(*f, problems_, range_of(section, "speed"));
    speed_key = f->key;
    speed_line = f->line;
  }
  if (!speed && !speed_missing_ && !view.has("speed")) {
    problems_.add(field.key_line, field.key, "no print speed: give toolpath.speed or speed: here");
    speed_missing_ = true;
  }
  if (problems_.size() != problems_before || surface->file.empty() || !speed) return;

  // read and place the part; hatch it
  std::shared_ptr<const SurfaceProjector> projector;
  SurfaceHatch hatch;
  Vec3 part_size = Vec3::Zero();  // the placed part's extent, for messages
  const Field* file_field = view.find("file");
  try {
    TriangleMesh part = read_stl(surface->file, surface->mm_per_unit, field.key + ".file");
    const Eigen::Matrix3d rotation =
        (Eigen::AngleAxisd(deg_to_rad(surface->rotation_deg.z()), Vec3::UnitZ()) *
         Eigen::AngleAxisd(deg_to_rad(surface->rotation_deg.y()), Vec3::UnitY()) *
         Eigen::AngleAxisd(deg_to_rad(surface->rotation_deg.x()), Vec3::UnitX()))
            .toRotationMatrix();
    // whether the file as written faces up, where a rotation may turn it over
    bool file_faced_down = true;
    if (!surface->rotation_deg.isZero()) {
      TriangleMesh as_written = part;
      as_written.orient_consistently();
      file_faced_down = as_written.face_outward_and_up();
    }
    part.transform(rotation, surface->offset_mm);
    // facets wound against their neighbours turned to match them, then an STL wound the wrong
    // way (a surface patch facing down, a solid inside out) turned over; every run says so:
    // the hatch looks for the faces seen from above
    const TriangleMesh::Orientation oriented = part.orient_consistently();
    if (oriented.unorientable_pieces > 0)
      scenario_.notes.push_back(
          "toolpath.surface: " + std::to_string(oriented.unorientable_triangles) + " of " +
          std::to_string(part.triangle_count()) + " triangles of '" + given_file + "' form " +
          (oriented.unorientable_pieces == 1 ? "a surface" : "surfaces") +
          " that cannot be wound consistently (one side runs into the other, as on a Moebius "
          "strip); each now faces up on its own, so the side seen from above is printed");
    else if (oriented.turned > 0)
      scenario_.notes.push_back("toolpath.surface: " + std::to_string(oriented.turned) + " of " +
                                std::to_string(part.triangle_count()) + " triangles of '" +
                                given_file +
                                "' were wound against their neighbours; they were turned over "
                                "to match them");
    if (part.face_outward_and_up())
      scenario_.notes.push_back(
          "toolpath.surface: '" + given_file +
          (file_faced_down
               ? "' faced down or inside out (its triangles wound clockwise seen "
                 "from outside); its triangles were turned over"
               : "' faces down as rotation [" + format_number(surface->rotation_deg.x()) + ", " +
                     format_number(surface->rotation_deg.y()) + ", " +
                     format_number(surface->rotation_deg.z()) +
                     "] places it (the file faces up); its triangles were turned "
                     "over, so the side now on top is printed"));
    // the grid's size before it is built: every layer's points over the part's (x, y) bounds
    Vec3 lo, hi;
    part.bounds(lo, hi);
    part_size = hi - lo;
    const double grid_points = ((hi.x() - lo.x()) / surface->hatch_mm + 2.0) *
                               ((hi.y() - lo.y()) / surface->hatch_mm + 2.0) * surface->layers;
    if (grid_points > kMaxSurfaceGridPoints) {
      problems_.add(
          field.key_line, field.key,
          "the hatch would have about " + format_number(std::round(grid_points)) +
              " grid points (" + std::to_string(surface->layers) + " layers over the part's " +
              format_number(hi.x() - lo.x()) + " x " + format_number(hi.y() - lo.y()) + " mm at " +
              format_number(surface->hatch_mm) + " mm), more than " +
              format_number(kMaxSurfaceGridPoints) + ": check units, hatch_mm and layers");
      return;
    }
    SurfaceHatchSpec spec;
    spec.hatch_mm = surface->hatch_mm;
    spec.angles_deg = surface->angles_deg;
    spec.layers = surface->layers;
    spec.layer_height_mm = surface->layer_height_mm;
    spec.alpha = surface->alpha;
    spec.offset = surface->layer_offset == "z" ? SurfaceHatchSpec::Offset::z
                                               : SurfaceHatchSpec::Offset::normal;
    spec.speed_mm_s = *speed;
    spec.chord_tolerance_mm = surface->chord_tolerance_mm;
    projector = std::make_shared<const SurfaceProjector>(std::move(part));
    hatch = hatch_surface(*projector, spec);
    // grid points no line prints (a stretch narrower than two spacings: a groove's floor), at
    // an angle where they are more than kLonePointsNoted of its grid: every run says so
    for (const LoneGridPoints& lone : hatch.lone_points) {
      if (lone.count <= kLonePointsNoted * lone.grid_points) continue;
      scenario_.notes.push_back(
          "toolpath.surface: at " + format_number(lone.angle_deg) + "°, " +
          std::to_string(lone.count) + " of the " + std::to_string(lone.grid_points) +
          " up-facing grid points of '" + given_file + "' (within " +
          box_text(lone.lower_mm, lone.upper_mm) +
          " mm) stand alone between steps or walls (a stretch narrower than two "
          "hatch_mm spacings, such as a groove's floor): a line needs two points, so lines at "
          "that angle leave them bare; a smaller hatch_mm reaches them");
    }
    // the hatch prints what is seen from above: an up-facing area under another part of the
    // surface (a shelf under an overhang) gets nothing, and every run says so
    const HiddenSurface hidden = hidden_top_surface(*projector, spec.min_normal_z);
    if (hidden.hidden_area_mm2 > kHiddenAreaNoted * hidden.up_area_mm2) {
      scenario_.notes.push_back(
          "toolpath.surface: " +
          format_number(std::round(1000.0 * hidden.hidden_area_mm2 / hidden.up_area_mm2) / 10.0) +
          " % of the up-facing area of '" + given_file + "' (" +
          format_number(std::round(hidden.hidden_area_mm2)) + " of " +
          format_number(std::round(hidden.up_area_mm2)) + " mm², within " +
          box_text(hidden.lower_mm, hidden.upper_mm) +
          " mm) lies under another part of the surface: the hatch is projected from above "
          "onto the top surface only, so that area gets no deposit");
    }
  } catch (const InputError& e) {
    // the reader's and the hatch's problems name this file and line
    for (Problem p : e.problems()) {
      if (p.file.empty() || p.file == surface->file) {
        // "'part.stl' line 12: ..." where the STL reader names its line
        const std::string stl_line = p.line > 0 ? " line " + std::to_string(p.line) : "";
        p.message =
            (p.file.empty() ? std::string() : "'" + given_file + "'" + stl_line + ": ") + p.message;
        p.file = problems_.file();
        // (the file's own problems at its `file:` line)
        p.line = p.key == field.key + ".file" && file_field ? file_field->line : field.key_line;
      }
      problems_.add_problem(p);
    }
    return;
  }
  if (hatch.toolpath.paths.empty()) {
    problems_.add(field.key_line, field.key,
                  "the hatch found no printable surface on '" + given_file +
                      "' (seen from above, no hatch line crosses it in two points: hatch_mm " +
                      format_number(surface->hatch_mm) + " mm over the part's " +
                      format_number(part_size.x()) + " x " + format_number(part_size.y()) +
                      " mm; check hatch_mm, units, offset and rotation)");
    return;
  }
  // the surface printed on stands on the work surface, z = 0 (the top of the table, bed or
  // plate: the part's own body may reach below it, into a fixture): no print point below it
  double lowest_z = std::numeric_limits<double>::infinity();
  for (const PrintPath& path : hatch.toolpath.paths)
    for (const Vec3& p : path.points) lowest_z = std::min(lowest_z, p.z());
  if (lowest_z < -kWorkSurfaceTolerance_mm) {
    const Vec3 raised = surface->offset_mm - Vec3(0, 0, lowest_z);
    problems_.add(field.key_line, field.key,
                  "the hatch on '" + given_file + "' reaches z = " + format_number(lowest_z) +
                      " mm, below the work surface (z = 0, the top of the table, bed or plate "
                      "the part stands on): the nozzle would be inside it; raise the part: "
                      "offset: [" +
                      format_number(raised.x()) + ", " + format_number(raised.y()) + ", " +
                      format_number(raised.z()) + "]");
    return;
  }

  // the paths, where each came from, and a start and end above the part by default (a
  // segment too fast is named by its layer, line and segment at the speed's key; check_path
  // lists the first kMaxSpeedProblems of them and counts the rest)
  Toolpath& toolpath = scenario_.toolpath;
  for (std::size_t i = 0; i < hatch.toolpath.paths.size(); ++i) {
    PrintPath path = hatch.toolpath.paths[i];
    path.source_index = static_cast<int>(i);
    PathOrigin path_origin{problems_.file(), field.key,
                           std::vector<int>(path.points.size(), field.key_line), true};
    path_origin.path_name = "layer " + std::to_string(hatch.info[i].layer) + ", line " +
                            std::to_string(hatch.info[i].line);
    path_origin.speed_key = speed_key;
    path_origin.speed_line = speed_line > 0 ? speed_line : field.key_line;
    check_path(path, path_origin);
    toolpath.paths.push_back(std::move(path));
    SurfaceToolpath::PathOrigin origin;
    origin.layer = hatch.info[i].layer;
    origin.line = hatch.info[i].line;
    origin.point_index = hatch.info[i].point_index;
    surface->origins.push_back(std::move(origin));
  }
  const Vec3& lo = projector->lower_bound();
  const Vec3& hi = projector->upper_bound();
  const Vec3 above((lo.x() + hi.x()) / 2, (lo.y() + hi.y()) / 2,
                   hi.z() + kSurfaceClearance_mm + surface->layers * surface->layer_height_mm);
  if (!start_given) toolpath.start_mm = above;
  if (!end_given) toolpath.end_mm = start_given ? toolpath.start_mm : above;
  scenario_.surface = std::move(surface);
  scenario_.part = std::shared_ptr<const TriangleMesh>(projector, &projector->mesh());
  scenario_.part_projector = std::move(projector);
}

void Loader::check_path(const PrintPath& path, const PathOrigin& origin) {
  // remembered for the checks after loading (reach) and for the job's messages
  if (path.source_index >= 0) {
    const std::size_t index = static_cast<std::size_t>(path.source_index);
    if (scenario_.path_sources.size() <= index) scenario_.path_sources.resize(index + 1);
    scenario_.path_sources[index] = PathSource{origin.file, origin.key, origin.point_lines};
  }
  for (std::size_t k = 0; k + 1 < path.points.size(); ++k) {
    const std::string segment =
        (origin.path_name.empty() ? "" : origin.path_name + ", ") +
        (origin.name_segments ? "segment " + std::to_string(k) + " (points " + std::to_string(k) +
                                    " and " + std::to_string(k + 1) + ")"
                              : "segment");
    const Vec3 step = path.points[k + 1] - path.points[k];
    const double length_mm = step.norm();
    // a segment's problem at the line of its end point, a whole path's (a `segments` entry, a
    // hatch line) at its first
    const int line = origin.point_lines.at(origin.name_segments ? k + 1 : 0);
    // consecutive points must differ
    if (length_mm <= kJoinTolerance_mm) {
      // (points closer than the tolerance but not equal are named both, with the distance)
      const std::string where = length_mm == 0.0
                                    ? "both points are " + format_point(path.points[k])
                                    : "the points " + format_point(path.points[k]) + " and " +
                                          format_point(path.points[k + 1]) + " are " +
                                          format_number(length_mm) + " mm apart, within the " +
                                          format_number(kJoinTolerance_mm) + " mm join tolerance";
      problems_.add_problem(
          Problem{origin.file, line, origin.key,
                  segment + " has zero length: " + where + " (consecutive points must differ)"});
      continue;
    }
    if (path.speed_mm_s <= 0.0) continue;
    // every axis must reach its share of the print speed, under the limits over this segment
    // (the machine's joint limits mapped to it, as the planners get them)
    const MachineLimits limits =
        tcp_limits_ ? tcp_limits_->along(path.points[k], path.points[k + 1]) : scenario_.limits;
    static const char* kAxisNames[3] = {"x", "y", "z"};
    int worst_axis = -1;
    double worst_ratio = 1.0 + kSpeedTolerance;
    for (int axis = 0; axis < 3; ++axis) {
      if (!axis_v_max_known_[axis]) continue;
      const double needed_mm_s = path.speed_mm_s * std::abs(step[axis]) / length_mm;
      const double ratio = needed_mm_s / limits.axes[axis].v_max_mm_s;
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst_axis = axis;
      }
    }
    if (worst_axis < 0) continue;
    // every segment over speed is reported, up to a count (a G-code file may have thousands)
    if (++speed_problems_ > kMaxSpeedProblems) continue;
    const double needed_mm_s = path.speed_mm_s * std::abs(step[worst_axis]) / length_mm;
    const double requested_mm_s = scenario_.limits.axes[worst_axis].v_max_mm_s;
    const double mapped_mm_s = limits.axes[worst_axis].v_max_mm_s;
    const std::string limit_text =
        mapped_mm_s < requested_mm_s * (1.0 - kSpeedTolerance)
            ? "above v_max " + format_speed(mapped_mm_s) + " here (" + scenario_.machine +
                  "'s joint limits mapped over this segment; limits v_max is " +
                  format_speed(requested_mm_s) + ")"
            : "above limits v_max " + format_speed(requested_mm_s);
    last_listed_speed_problem_ =
        Problem{origin.file, origin.speed_key.empty() ? line : origin.speed_line,
                origin.speed_key.empty() ? origin.key : origin.speed_key,
                (origin.name_segments ? segment + ": " : std::string()) + "print speed " +
                    format_speed(path.speed_mm_s) + " mm/s needs " + format_speed(needed_mm_s) +
                    " mm/s on " + kAxisNames[worst_axis] + ", " + limit_text +
                    " (lower the speed or raise the limit)"};
    problems_.add_problem(last_listed_speed_problem_);
  }
}

void Loader::read_arm(const Field& field) {
  scenario_.arm_line = field.key_line;
  const MapView view(field, keys_of("arm"), problems_);
  if (!view.is_map()) return;
  ArmPostureSettings arm;
  if (const Field* f = view.find("roll")) {
    const std::optional<std::string> roll = read_string(*f, problems_);
    if (roll && (*roll == "optimized" || *roll == "fixed"))
      arm.optimize_roll = *roll == "optimized";
    else if (roll)
      problems_.add(f->line, f->key,
                    "unknown roll strategy '" + *roll +
                        "' (expected optimized: chosen point by point, or fixed: one roll)");
  }
  if (const Field* f = view.find("fixed_roll_deg")) {
    arm.fixed_roll_deg = read_number(*f, problems_, range_of("arm", "fixed_roll_deg"));
    if (arm.optimize_roll && arm.fixed_roll_deg)
      problems_.add(f->line, f->key, "applies to roll: fixed only");
  }
  if (const Field* f = view.find("branch"))
    arm.branch = static_cast<int>(
        read_integer(*f, problems_, min_of("arm", "branch"), max_of("arm", "branch"))
            .value_or(arm.branch));
  const auto read = [&](const char* key, double& target) {
    if (const Field* f = view.find(key))
      target = read_number(*f, problems_, range_of("arm", key)).value_or(target);
  };
  read("roll_step_deg", arm.roll_step_deg);
  // the ladder's rolls go round once: a step that does not divide 360 is named at its line
  if (const Field* f = view.find("roll_step_deg");
      f != nullptr && !roll_step_divides_a_turn(arm.roll_step_deg)) {
    problems_.add(f->line, f->key,
                  "must divide 360 into a whole number of steps (5, 7.5, 10, 15, 30, ...), got " +
                      format_number(arm.roll_step_deg));
    arm.roll_step_deg = ArmPostureSettings().roll_step_deg;
  }
  read("sample_spacing_mm", arm.sample_spacing_mm);
  read("min_joint_margin_deg", arm.min_joint_margin_deg);
  read("min_wrist_alignment", arm.min_wrist_alignment);
  read("min_wrist_offset_mm", arm.min_wrist_offset_mm);
  read("min_manipulability", arm.min_manipulability);
  read("min_clearance_mm", arm.min_clearance_mm);
  read("max_joint_step_deg", arm.max_joint_step_deg);
  const std::string problem = arm.validate();
  if (!problem.empty()) problems_.add(field.key_line, field.key, problem);
  scenario_.arm = arm;
}

bool Loader::read_order_name(const Field& field, OrderSpec& order) {
  const std::optional<std::string> text = read_string(field, problems_);
  if (!text) return false;
  const std::string problem = parse_order_name(*text, order);
  if (!problem.empty()) {
    problems_.add(field.line, field.key, problem);
    return false;
  }
  return true;
}

void Loader::read_order(const Field& field) {
  OrderSpec& order = scenario_.order;
  if (field.node.IsScalar()) {
    read_order_name(field, order);
    return;
  }
  if (!field.node.IsMap()) {
    problems_.add(field.line, field.key,
                  "expected a sequencer name or {method, refine, cost_model, seed}, got " +
                      describe(field.node));
    return;
  }
  const MapView view(field, keys_of("order"), problems_);
  bool method_refines = false;
  if (const Field* f = view.find("method")) {
    if (read_order_name(*f, order)) method_refines = !order.refine.empty();
  }
  if (const Field* f = view.find("refine")) {
    const std::optional<std::string> refine = read_string(*f, problems_);
    if (refine && !contains(refine_methods(), *refine) && *refine != "none") {
      problems_.add(
          f->line, f->key,
          "unknown refinement '" + *refine + "' (expected " + join(refine_methods()) + " or none)");
    } else if (refine && method_refines && *refine != order.refine) {
      problems_.add(f->line, f->key,
                    "method already implies refine " + order.refine + "; give one refinement");
    } else if (refine) {
      order.refine = *refine == "none" ? "" : *refine;
    }
  }
  if (const Field* f = view.find("cost_model")) {
    const std::optional<std::string> model = read_string(*f, problems_);
    if (model && !contains(cost_models(), *model))
      problems_.add(f->line, f->key,
                    "unknown cost model '" + *model + "' (expected " + join(cost_models()) + ")");
    else if (model)
      order.cost_model = *model;
  }
  if (const Field* f = view.find("seed"))
    order.seed = read_seed(*f, problems_).value_or(order.seed);
}

MachineLimits Loader::limits_in_force() const {
  if (!tcp_limits_ || scenario_.toolpath.paths.empty()) return scenario_.limits;
  Vec3 lo, hi;
  scenario_.toolpath.bounds(lo, hi);
  return tcp_limits_->over(lo, hi);
}

void Loader::read_planners(const Field& field) {
  if (!expect_list(field, problems_,
                   "a list of planners, e.g. [lspb_mtt, {name: bezier, delta: 0.3}]"))
    return;
  if (field.node.size() == 0) {
    problems_.add(field.line, field.key, "is empty: name at least one planner");
    return;
  }
  std::vector<PlannerSpec> planners;
  for (std::size_t i = 0; i < field.node.size(); ++i) {
    const Field item = field.item(i);
    PlannerSpec spec;
    spec.line = item.line;
    std::vector<const Field*> parameter_fields;
    std::optional<MapView> view;
    if (item.node.IsScalar()) {
      spec.name = item.node.Scalar();
    } else if (item.node.IsMap()) {
      // {name: X, <parameter>: number | [numbers]}: every key but name is a parameter
      std::vector<std::string> keys;
      for (const auto& key_value : item.node)
        if (key_value.first.IsScalar()) keys.push_back(key_value.first.Scalar());
      view.emplace(item, keys, problems_);
      const Field* name = view->find("name");
      if (!name) {
        problems_.add(item.line, item.key, "missing name: (which planner)");
        continue;
      }
      const std::optional<std::string> text = read_string(*name, problems_);
      if (!text) continue;
      spec.name = *text;
      for (const std::string& key : keys)
        if (key != "name" && view->find(key)) parameter_fields.push_back(view->find(key));
    } else {
      problems_.add(
          item.line, item.key,
          "expected a planner name or {name: X, parameter: value}, got " + describe(item.node));
      continue;
    }
    // the name first, then each parameter on its own line
    const std::string name_problem = check_planner_spec(PlannerSpec{spec.name, {}, spec.line});
    if (!name_problem.empty()) {
      problems_.add(item.line, item.key, name_problem);
      continue;
    }
    // a jerk limit the planner would ignore (the user's, or the joints' mapped to the TCP)
    const std::string limits_problem = check_planner_limits(spec, limits_in_force());
    if (!limits_problem.empty()) problems_.add(item.line, item.key, limits_problem);
    for (const Field* parameter : parameter_fields) {
      const std::string key = parameter->key.substr(parameter->key.rfind('.') + 1);
      // `label:` names the run (its results folder) when a planner runs more than once
      if (key == "label") {
        const std::optional<std::string> label = read_string(*parameter, problems_);
        if (!label) continue;
        std::string problem = folder_name_problem(*label);
        if (problem.empty() && label->find(' ') != std::string::npos)
          problem = "'" + printable_text(*label) + "' cannot name a run (no spaces)";
        if (problem.empty() && names_an_output_file(*label))
          problem = "'" + printable_text(*label) +
                    "' cannot name a run: the run folders sit beside the output folder's own "
                    "files (.depotwin, comparison.json, .csv, .md, .png; a sweep task's "
                    "task.json), and a name starting with '.' is hidden";
        if (!problem.empty())
          problems_.add(parameter->line, parameter->key, problem);
        else
          spec.label = *label;
        continue;
      }
      // a choice parameter takes a word from its list
      const PlannerInfo* info = find_planner(spec.name);
      const auto declared = std::find_if(info->parameters.begin(), info->parameters.end(),
                                         [&](const PlannerParameter& p) { return p.name == key; });
      if (declared != info->parameters.end() && !declared->choices.empty()) {
        const std::optional<std::string> word = read_string(*parameter, problems_);
        if (!word) continue;
        PlannerSpec single{spec.name, {}, spec.line, {{key, *word}}};
        const std::string problem = check_planner_spec(single);
        if (!problem.empty())
          problems_.add(parameter->line, parameter->key, problem);
        else
          spec.choices[key] = *word;
        continue;
      }
      std::vector<double> values;
      bool ok = true;
      if (parameter->node.IsSequence()) {
        if (parameter->node.size() == 0) {
          problems_.add(parameter->line, parameter->key, "is an empty list: give a number");
          continue;
        }
        for (std::size_t j = 0; j < parameter->node.size(); ++j) {
          const std::optional<double> value = read_number(parameter->item(j), problems_);
          ok = ok && value.has_value();
          values.push_back(value.value_or(0.0));
        }
      } else {
        const std::optional<double> value = read_number(*parameter, problems_);
        ok = value.has_value();
        values.push_back(value.value_or(0.0));
      }
      if (!ok) continue;
      PlannerSpec single{spec.name, {{key, values}}, spec.line};
      const std::string problem = check_planner_spec(single);
      if (!problem.empty()) {
        problems_.add(parameter->line, parameter->key, problem);
        continue;
      }
      spec.params[key] = values;
    }
    // each run once: results are written per label (the planner's name unless given)
    const bool repeated = std::any_of(planners.begin(), planners.end(), [&](const PlannerSpec& p) {
      return p.run_label() == spec.run_label();
    });
    if (repeated) {
      problems_.add(
          item.line, item.key,
          spec.label.empty()
              ? "planner '" + spec.name + "' is listed twice (give each a label: to run it twice)"
              : "label '" + spec.label + "' is used twice");
      continue;
    }
    planners.push_back(std::move(spec));
  }
  scenario_.planners = std::move(planners);
}

void Loader::read_sim(const Field& field) {
  const MapView view(field, keys_of("sim"), problems_);
  SimSpec& sim = scenario_.sim;
  const auto read = [&](const char* key, double& target) {
    if (const Field* f = view.find(key))
      target = read_number(*f, problems_, range_of("sim", key)).value_or(target);
  };
  read("timestep_s", sim.timestep_s);
  // the servo update period: a whole number of physics steps, by default the one nearest
  // to 1 ms
  sim.control_period_s = sim.timestep_s * std::max(1.0, std::round(0.001 / sim.timestep_s));
  if (const Field* f = view.find("control_period_s")) {
    if (auto period = read_number(*f, problems_, range_of("sim", "control_period_s"))) {
      const double steps = *period / sim.timestep_s;
      if (std::abs(steps - std::round(steps)) > 1e-9 * steps || std::round(steps) < 1)
        problems_.add(
            f->line, f->key,
            "must be a whole multiple of sim.timestep_s (" + format_number(sim.timestep_s) + " s)");
      else
        sim.control_period_s = *period;
    }
  }
  read("cell_mm", sim.cell_mm);
  read("kp_scale", sim.kp_scale);
  read("settle_s", sim.settle_s);
  if (const Field* f = view.find("max_steps"))
    sim.max_steps =
        read_integer(*f, problems_, min_of("sim", "max_steps"), max_of("sim", "max_steps"))
            .value_or(sim.max_steps);
}

void Loader::check_settings() {
  const SimSpec& sim = scenario_.sim;
  const ProcessSpec& process = scenario_.process;
  const std::map<std::string, int>& lines = problems_.key_lines();
  const auto line_of = [&](const std::string& key) {
    const auto found = lines.find(key);
    return found == lines.end() ? 0 : found->second;
  };
  // the deposition grid against the footprint it samples (deposition/process.cpp enforces the
  // same bounds): sigma / 64 .. sigma
  const int cell_line = line_of("sim.cell_mm");
  if (cell_line > 0 && sim.cell_mm > 0.0) {
    const bool aerosol = process.type == "aerosol";
    const double sigma_mm = aerosol ? process.sigma_mm : 0.25 * process.bead_width_mm;
    const double lo_mm = input_ranges::kMinCellSigmas * sigma_mm;
    const double hi_mm = input_ranges::kMaxCellSigmas * sigma_mm;
    if (sim.cell_mm < lo_mm * (1.0 - 1e-12) || sim.cell_mm > hi_mm * (1.0 + 1e-12))
      problems_.add(cell_line, "sim.cell_mm",
                    "must be 0 (the default) or between sigma / 64 = " + format_number(lo_mm) +
                        " and sigma = " + format_number(hi_mm) + " mm of the footprint (" +
                        (aerosol ? "process.sigma_mm" : "process.bead_width_mm / 4") + "), got " +
                        format_number(sim.cell_mm));
  }
  // the servo loop's stability: kp dt^2 (sim/servo_controller: an explicit loop)
  const double stiffness =
      sim.kp_scale * std::pow(sim.timestep_s / input_ranges::kReferenceTimestep_s, 2);
  const double max_stiffness = input_ranges::max_servo_stiffness_per_step(scenario_.machine);
  if (stiffness > max_stiffness * (1.0 + 1e-12)) {
    const int kp_line = line_of("sim.kp_scale");
    const int step_line = line_of("sim.timestep_s");
    problems_.add(step_line > 0 ? step_line : kp_line,
                  step_line > 0 ? "sim.timestep_s" : "sim.kp_scale",
                  "timestep_s " + format_number(sim.timestep_s) + " s with kp_scale " +
                      format_number(sim.kp_scale) +
                      " makes the servos unstable: kp_scale * "
                      "(timestep_s / 1 ms)^2 = " +
                      format_number(stiffness) + ", at most " + format_number(max_stiffness) +
                      " on " + scenario_.machine + " (lower sim.timestep_s or sim.kp_scale)");
  }
}

void Loader::read_outputs(const Field& field) {
  const MapView view(field, keys_of("outputs"), problems_);
  OutputSpec& outputs = scenario_.outputs;
  if (const Field* f = view.find("render"))
    outputs.render = read_bool(*f, problems_).value_or(outputs.render);
  const auto read = [&](const char* key, int& target) {
    if (const Field* f = view.find(key))
      target = static_cast<int>(
          read_integer(*f, problems_, min_of("outputs", key), max_of("outputs", key))
              .value_or(target));
  };
  read("image_width", outputs.image_width);
  read("image_height", outputs.image_height);
}

}  // namespace

std::string SurfaceToolpath::describe_point(int source_index, size_t point, size_t point_count,
                                            bool reversed) const {
  if (source_index < 0 || static_cast<size_t>(source_index) >= origins.size())
    return "path " + std::to_string(source_index) + ", point " + std::to_string(point);
  const PathOrigin& origin = origins[static_cast<size_t>(source_index)];
  const size_t i = reversed ? point_count - 1 - point : point;
  const int along = i < origin.point_index.size() ? origin.point_index[i] : static_cast<int>(i);
  return "layer " + std::to_string(origin.layer) + ", line " + std::to_string(origin.line) +
         ", point " + std::to_string(along);
}

Problem path_point_problem(const Scenario& scenario, int source_index, std::size_t point,
                           const std::string& message) {
  // a hatched surface: by layer, line and point, at the `surface:` key
  if (scenario.surface) {
    const PrintPath* given = nullptr;
    for (const PrintPath& path : scenario.toolpath.paths)
      if (path.source_index == source_index) given = &path;
    const std::size_t count = given ? given->points.size() : point + 1;
    return Problem{
        scenario.file, scenario.surface->line, "toolpath.surface",
        scenario.surface->describe_point(source_index, point, count, false) + ": " + message};
  }
  // a path of the file (or of its G-code): its key and the point's line
  if (source_index >= 0 && static_cast<std::size_t>(source_index) < scenario.path_sources.size()) {
    const PathSource& source = scenario.path_sources[static_cast<std::size_t>(source_index)];
    if (!source.key.empty()) {
      const int line = point < source.point_lines.size() ? source.point_lines[point] : 0;
      return Problem{source.file, line, source.key,
                     "point " + std::to_string(point) + " " + message};
    }
  }
  return Problem{
      scenario.file, scenario.toolpath_line, "toolpath",
      "path " + std::to_string(source_index) + ", point " + std::to_string(point) + " " + message};
}

Problem path_problem(const Scenario& scenario, int source_index, const std::string& detail,
                     const std::string& message) {
  const std::string below = detail.empty() ? "" : "." + detail;
  // a hatched surface: its layer and hatch line, at the toolpath's key for the detail (its
  // `speed:`) when given, else at the `surface:` key
  if (scenario.surface) {
    const auto& origins = scenario.surface->origins;
    std::string where = "path " + std::to_string(source_index);
    if (source_index >= 0 && static_cast<std::size_t>(source_index) < origins.size()) {
      const SurfaceToolpath::PathOrigin& origin = origins[static_cast<std::size_t>(source_index)];
      where = "layer " + std::to_string(origin.layer) + ", line " + std::to_string(origin.line);
    }
    const auto shared =
        detail.empty() ? scenario.key_lines.end() : scenario.key_lines.find("toolpath" + below);
    if (shared != scenario.key_lines.end())
      return Problem{scenario.file, shared->second, shared->first, where + ": " + message};
    return Problem{scenario.file, scenario.surface->line, "toolpath.surface",
                   where + ": " + message};
  }
  if (source_index >= 0 && static_cast<std::size_t>(source_index) < scenario.path_sources.size()) {
    const PathSource& source = scenario.path_sources[static_cast<std::size_t>(source_index)];
    const int first_line = source.point_lines.empty() ? 0 : source.point_lines.front();
    // a path of a G-code file: the line of its first move, at the file's key
    if (!source.key.empty() && source.file != scenario.file)
      return Problem{source.file, first_line, source.key,
                     "the print path from this line: " + message};
    // a path of the scenario file: its own key for the detail when given (its `speed:`), else
    // its entry (its own line, not the toolpath's shared `speed:`): never a key the file
    // does not hold
    if (!source.key.empty()) {
      const auto own = scenario.key_lines.find(source.key + below);
      if (own != scenario.key_lines.end())
        return Problem{scenario.file, own->second, own->first, message};
      const int line = first_line > 0 ? first_line : scenario.line_of(source.key);
      return Problem{scenario.file, line, source.key, message};
    }
  }
  return Problem{scenario.file, scenario.toolpath_line, "toolpath",
                 "path " + std::to_string(source_index) + ": " + message};
}

namespace {

// Where the paths lie against the machine's reach, and the move that brings every path point
// within it, if centring them on the workspace does: in x and y first (the layers stay on the
// bed), else in z too. A slicer's file lies in its bed's frame, from 0; the machines here
// centre on 0 (the middle of every joint's travel).
std::string reach_summary(const Toolpath& toolpath, const Machine& machine, bool from_gcode) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const PrintPath& path : toolpath.paths)
    for (const Vec3& p : path.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  JointVector middle(machine.joint_count());
  for (int j = 0; j < machine.joint_count(); ++j) {
    const JointLimit& limit = machine.joint_limits()[static_cast<std::size_t>(j)];
    middle[j] = 0.5 * (limit.min + limit.max);
  }
  const Vec3 centre = machine.forward(middle).position_mm;
  const auto rounded = [](const Vec3& v) -> Vec3 {
    return Vec3((v.array() * 10.0).round() / 10.0) + Vec3::Zero();  // (+0: no -0 in messages)
  };
  const auto all_reachable = [&](const Vec3& shift) {
    JointVector joints;
    for (const PrintPath& path : toolpath.paths)
      for (std::size_t i = 0; i < path.points.size(); ++i)
        if (!machine.inverse(Pose(path.points[i] + shift, path.tool_axis(i)), joints)) return false;
    return true;
  };
  const Vec3 to_centre = centre - 0.5 * (lo + hi);
  const Vec3 in_plane = rounded(Vec3(to_centre.x(), to_centre.y(), 0.0));
  const Vec3 in_space = rounded(to_centre);
  // a print below z = 0 (a CNC file zeroed on its stock's top, a negative z offset): centred
  // in x and y and its lowest point lifted onto the bed, before the workspace's centre
  const Vec3 on_bed = in_plane + Vec3(0.0, 0.0, std::max(0.0, std::ceil(-lo.z() * 10.0) / 10.0));
  const auto range = [](double from, double to) {
    return from == to ? format_number(from) : format_number(from) + " to " + format_number(to);
  };
  const std::string message = "the print paths span x " + range(lo.x(), hi.x()) + ", y " +
                              range(lo.y(), hi.y()) + ", z " + range(lo.z(), hi.z()) + " mm; ";
  const Vec3 shifts[3] = {in_plane, on_bed, in_space};
  for (const Vec3& shift : shifts)
    if (all_reachable(shift))
      return message + "moved by " + format_point(shift) + " mm every point is within " +
             machine.name() + "'s reach: add that to toolpath.offset (" +
             (from_gcode ? "a slicer's file lies in its bed's frame, from 0; " : "") +
             machine.name() + " centres on " + format_point(rounded(centre)) + ")";
  return message + "even centred on " + machine.name() + "'s workspace (moved by " +
         format_point(in_space) + " mm) some are out of its reach: the print is larger than " +
         "the machine, or its shape does not fit the workspace";
}

}  // namespace

std::vector<std::string> scenario_input_files(const Scenario& scenario) {
  std::vector<std::string> files;
  if (scenario.gcode) files.push_back(scenario.gcode->file);
  if (scenario.surface) files.push_back(scenario.surface->file);
  if (!scenario.model_path.empty()) files.push_back(scenario.model_path);
  return files;
}

std::vector<Problem> unreachable_points(const Scenario& scenario, const Machine& machine,
                                        std::size_t max_listed) {
  std::vector<Problem> problems;
  std::size_t unlisted = 0;
  JointVector joints;
  // "(x, y, z) mm is not reachable by M: why", or nothing when reachable
  const auto unreachable = [&](const Pose& pose) -> std::optional<std::string> {
    std::string why;
    if (machine.inverse(pose, joints, &why)) return std::nullopt;
    const Vec3& p = pose.position_mm;
    return format_point(p) + " mm is not reachable by " + machine.name() + ": " + why;
  };
  const auto add = [&](Problem problem) {
    if (problems.size() < max_listed)
      problems.push_back(std::move(problem));
    else
      ++unlisted;
  };
  // start and end, at their keys (or the toolpath's line when they are defaults)
  const Toolpath& toolpath = scenario.toolpath;
  const int surface_line = scenario.surface ? scenario.surface->line : 0;
  const auto end_line = [&](int given) {
    return given > 0 ? given : surface_line > 0 ? surface_line : scenario.toolpath_line;
  };
  // (a default is the toolpath's first point: unknown while no path could be read)
  const bool defaults_known = !toolpath.paths.empty();
  if (const auto why = scenario.start_line > 0 || defaults_known
                           ? unreachable(Pose(toolpath.start_mm))
                           : std::nullopt)
    add(Problem{scenario.file, end_line(scenario.start_line), "toolpath.start",
                (scenario.start_line > 0 ? "" : "(the default) ") + *why});
  if (const auto why = scenario.end_line > 0 || defaults_known ? unreachable(Pose(toolpath.end_mm))
                                                               : std::nullopt)
    add(Problem{scenario.file, end_line(scenario.end_line), "toolpath.end",
                (scenario.end_line > 0 ? "" : "(the default) ") + *why});
  // every point of every path, where it was given
  bool path_out_of_reach = false;
  for (const PrintPath& path : toolpath.paths)
    for (std::size_t i = 0; i < path.points.size(); ++i)
      if (const auto why = unreachable(Pose(path.points[i], path.tool_axis(i)))) {
        add(path_point_problem(scenario, path.source_index, i, *why));
        path_out_of_reach = true;
      }
  // (after the last one listed, where it was given: the problems are sorted by line)
  if (unlisted > 0) {
    Problem more =
        problems.empty()
            ? Problem{scenario.file, surface_line > 0 ? surface_line : scenario.toolpath_line,
                      scenario.surface ? "toolpath.surface" : "toolpath", ""}
            : problems.back();
    more.message = "... and " + std::to_string(unlisted) + " more unreachable points (the first " +
                   std::to_string(max_listed) + " are listed)";
    problems.push_back(std::move(more));
  }
  if (path_out_of_reach) {
    // (at the offset when given, else at the toolpath)
    const auto offset = scenario.key_lines.find("toolpath.offset");
    problems.push_back(Problem{
        scenario.file, offset != scenario.key_lines.end() ? offset->second : scenario.toolpath_line,
        "toolpath.offset", reach_summary(toolpath, machine, scenario.gcode != nullptr)});
  }
  return problems;
}

int Scenario::line_of(const std::string& key) const {
  // the key itself, else its nearest given parent, else the top of the file
  for (std::string k = key; !k.empty();) {
    const auto found = key_lines.find(k);
    if (found != key_lines.end()) return found->second;
    const std::size_t dot = k.rfind('.');
    if (dot == std::string::npos) break;
    k.resize(dot);
  }
  return 1;
}

Problem Scenario::problem_at(const std::string& key, const std::string& message) const {
  return Problem{file, line_of(key), key, message};
}

std::vector<Problem> Scenario::located(std::vector<Problem> problems) const {
  static const std::string kPathKey = "toolpath.paths[";
  for (Problem& p : problems) {
    if (!p.file.empty()) continue;
    // "toolpath.paths[N]" or "toolpath.paths[N].detail": path N's own source
    if (p.key.compare(0, kPathKey.size(), kPathKey) == 0) {
      const std::size_t close = p.key.find(']', kPathKey.size());
      const std::string index = close == std::string::npos
                                    ? std::string()
                                    : p.key.substr(kPathKey.size(), close - kPathKey.size());
      if (!index.empty() && index.size() < 10 &&
          std::all_of(index.begin(), index.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        const std::string detail = close + 2 <= p.key.size() && p.key[close + 1] == '.'
                                       ? p.key.substr(close + 2)
                                       : std::string();
        p = path_problem(*this, std::stoi(index), detail, p.message);
        continue;
      }
    }
    p.file = file;
    p.line = line_of(p.key);
  }
  return problems;
}

void sort_problems(std::vector<Problem>& problems, const std::string& scenario_file) {
  // scenario-file problems in line order, then those of other files as found
  std::stable_sort(problems.begin(), problems.end(), [&](const Problem& a, const Problem& b) {
    const bool a_other = a.file != scenario_file, b_other = b.file != scenario_file;
    if (a_other != b_other) return !a_other;
    return !a_other && a.line < b.line;
  });
}

ScenarioReading read_scenario(const std::string& path) {
  return Loader(path).read();
}

Scenario load_scenario(const std::string& path) {
  ScenarioReading reading = read_scenario(path);
  if (!reading.problems.empty()) throw InputError(std::move(reading.problems));
  return std::move(reading.scenario);
}

Scenario load_scenario(const std::string& path, const std::string& text,
                       const std::vector<ScenarioOverride>& overrides) {
  Loader loader(path);
  loader.set_source(&text, &overrides);
  ScenarioReading reading = loader.read();
  if (!reading.problems.empty()) throw InputError(std::move(reading.problems));
  return std::move(reading.scenario);
}

std::vector<Problem> validate_scenario_file(const std::string& path) {
  try {
    load_scenario(path);
  } catch (const InputError& e) {
    return e.problems();
  }
  return {};
}

}  // namespace depotwin
