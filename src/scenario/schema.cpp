// The scenario schema's tables. Defaults are read from the structs the loader fills
// (ProcessSpec{}, SimSpec{}, ...), so a table cannot disagree with what a file without the
// key gets.
#include "scenario/schema.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/input_ranges.hpp"
#include "core/number_text.hpp"
#include "kinematics/machine.hpp"
#include "planners/ordering/sequencer.hpp"
#include "scenario/scenario.hpp"
#include "toolpath/random_segments.hpp"

namespace depotwin {

const char* const kJointAngleDefinition =
    "joint angle: the interior angle between two consecutive segments where they touch, "
    "180 deg = straight on, 90 deg = a square corner, 0 deg = a full reversal";

bool ValueRange::contains(double value) const {
  const bool above = min_inclusive ? value >= min : value > min;
  const bool below = max_inclusive ? value <= max : value < max;
  return above && below;
}

bool ValueRange::bounded() const {
  return std::isfinite(min) || std::isfinite(max);
}

std::string ValueRange::text() const {
  const bool has_min = std::isfinite(min);
  const bool has_max = std::isfinite(max);
  if (has_min && has_max)
    return std::string("in ") + (min_inclusive ? "[" : "(") + format_number(min) + ", " +
           format_number(max) + (max_inclusive ? "]" : ")");
  if (has_min) return std::string(min_inclusive ? ">= " : "> ") + format_number(min);
  if (has_max) return std::string(max_inclusive ? "<= " : "< ") + format_number(max);
  return "finite";
}

std::string format_number(double value) {
  return message_number(value);
}

std::string SchemaKey::accepted() const {
  if (!choices.empty()) {
    std::string list;
    for (const std::string& choice : choices) list += (list.empty() ? "" : " | ") + choice;
    return list;
  }
  if (range.bounded()) return range.text();
  return type;
}

std::vector<std::string> SchemaSection::key_names() const {
  std::vector<std::string> names;
  for (const SchemaKey& k : keys) names.push_back(k.name);
  return names;
}

const SchemaKey& SchemaSection::key(const std::string& name) const {
  for (const SchemaKey& k : keys)
    if (k.name == name) return k;
  throw std::out_of_range("schema section '" + path + "' has no key '" + name + "'");
}

namespace {

namespace ranges = input_ranges;

// (0, max]: a positive quantity with a sane ceiling
ValueRange positive_up_to(double max) {
  return {0.0, false, max, true};
}

// a number with its unit, range and default
SchemaKey number(const std::string& name, const std::string& unit, const ValueRange& range,
                 double default_value, const std::string& meaning,
                 const std::string& applies_to = "") {
  SchemaKey key;
  key.name = name;
  key.type = "number";
  key.unit = unit;
  key.range = range;
  key.default_text = format_number(default_value);
  key.default_value = default_value;
  key.meaning = meaning;
  key.applies_to = applies_to;
  return key;
}

// a whole number in [lo, hi]
SchemaKey whole(const std::string& name, const std::string& unit, double lo, double hi,
                double default_value, const std::string& meaning) {
  SchemaKey key = number(name, unit, ValueRange::closed(lo, hi), default_value, meaning);
  key.type = "whole number";
  return key;
}

// one word of a list
SchemaKey word(const std::string& name, const std::vector<std::string>& choices,
               const std::string& default_text, const std::string& meaning) {
  SchemaKey key;
  key.name = name;
  key.type = "word";
  key.choices = choices;
  key.default_text = default_text;
  key.meaning = meaning;
  return key;
}

// anything else: a point, a list, a map, a text
SchemaKey other(const std::string& name, const std::string& type, const std::string& unit,
                const std::string& default_text, const std::string& meaning) {
  SchemaKey key;
  key.name = name;
  key.type = type;
  key.unit = unit;
  key.default_text = default_text;
  key.meaning = meaning;
  return key;
}

std::vector<SchemaSection> make_schema() {
  const ProcessSpec process;
  const SimSpec sim;
  const OutputSpec outputs;
  const SurfaceToolpath surface;
  const RandomSegmentsSpec random;
  const ArmPostureSettings arm;
  const OrderSpec order;
  std::vector<SchemaSection> schema;

  // the top level
  schema.push_back(
      {"",
       "a scenario file: one YAML map; every key optional except toolpath",
       {other("name", "text", "", "the file's stem",
              "names the results folder: 1 to 100 bytes of printable text (no control "
              "characters), no '/' or '\\', not '.' or '..'"),
        [] {
          SchemaKey key = word("machine", machine_names(), "xy_stage",
                               "a registered machine, or {model: FILE.xml, kinematics: NAME} for "
                               "an MJCF model of one's own (see `depotwin describe machines`)");
          key.type = "word or map";
          return key;
        }(),
        other("limits", "map", "", "v_max 4, a_max 30, no j_max",
              "the TCP's limits per axis (see `depotwin describe limits`)"),
        other("process", "map", "", "aerosol",
              "how material leaves the nozzle (see `depotwin describe processes`)"),
        other("toolpath", "map", "", "required",
              "the print paths (see `depotwin describe toolpath`)"),
        other("arm", "map", "", "optimized roll, best branch",
              "arm6 only: roll and IK branch along the toolpath (see `depotwin describe arm`)"),
        other("order", "word or map", "", "as_given",
              "the print order (see `depotwin describe sequencers`)"),
        other("planners", "list", "", "[lspb_mtt, stop_and_go]",
              "names or {name: X, label: L, <parameter>: value} (see `depotwin describe "
              "planners`)"),
        other("sim", "map", "", "see sim", "simulation settings (see `depotwin describe sim`)"),
        other("outputs", "map", "", "see outputs",
              "what a run writes (see `depotwin describe outputs`)")}});

  // limits: common values, per-axis overrides, joint limits
  const auto axis_keys = [](const std::string& scope, bool joint) {
    const std::string v_unit = joint ? "mm/s or deg/s" : "mm/s";
    const std::string a_unit = joint ? "mm/s^2 or deg/s^2" : "mm/s^2";
    SchemaKey v =
        number("v_max", v_unit, ValueRange::closed(ranges::kMinLimit, ranges::kMaxSpeed_mm_s),
               kDefaultTcpVMax_mm_s, "speed limit " + scope);
    SchemaKey a = number("a_max", a_unit,
                         ValueRange::closed(ranges::kMinLimit, ranges::kMaxAcceleration_mm_s2),
                         kDefaultTcpAMax_mm_s2, "acceleration limit " + scope);
    SchemaKey j =
        number("j_max", "mm/s^3", ValueRange::closed(0.0, ranges::kMaxJerk_mm_s3), 0.0,
               "jerk limit " + scope + ", 0 or at least " + format_number(ranges::kMinLimit) +
                   "; 0: none (above 0 every planner plans jerk-limited motion; "
                   "lspb_mtt and stop_and_go then plan double-S moves)");
    if (joint) {
      v.default_text = a.default_text = "required";
      v.default_value = a.default_value = std::nullopt;
    }
    return std::vector<SchemaKey>{v, a, j};
  };
  {
    std::vector<SchemaKey> keys = axis_keys("of every TCP axis (x, y, z)", false);
    keys.push_back(
        other("x", "map", "", "the common values", "x's own v_max, a_max, j_max (see limits.x)"));
    keys.push_back(other("y", "map", "", "the common values", "y's own, as x"));
    keys.push_back(other("z", "map", "", "the common values", "z's own, as x"));
    keys.push_back(other("joint", "map", "", "the machine's own (see machines)",
                         "the same limits on every joint of the machine, in its unit: mm for "
                         "carriages, deg for hinges (see limits.joint)"));
    schema.push_back({"limits",
                      "the TCP's limits (the machine maps its joint limits to each move's box, "
                      "never looser than these)",
                      keys});
  }
  {
    // an axis' own limit defaults to the common one (limits.v_max, ...), whatever that is
    std::vector<SchemaKey> keys = axis_keys("of this TCP axis", false);
    for (SchemaKey& key : keys) {
      key.default_text = "limits." + key.name;
      key.default_value = std::nullopt;
    }
    schema.push_back({"limits.x", "one TCP axis' overrides (also limits.y, limits.z)", keys});
  }
  schema.push_back({"limits.joint",
                    "every joint alike; a joint j_max is refused on linear_delta and arm6",
                    axis_keys("of every joint", true)});

  // process
  schema.push_back(
      {"process",
       "how material leaves the nozzle: an aerosol stream with a shutter, or extrusion",
       {word("type", {"aerosol", "extrusion"}, process.type,
             "aerosol: a stream from job start to end, Gaussian footprint, a flap shutter; "
             "extrusion: commanded flow with a first-order lag"),
        number("flow_mm3_s", "mm^3/s", ValueRange::closed(0.0, 1e6), process.flow_mm3_s,
               "aerosol: the stream's flow, 0: a straight line at 3 mm/s peaks at 2 um (Q = 2 um "
               "* 3 mm/s * sigma * sqrt(2 pi)); extrusion: a fixed nominal flow (a constant-rate "
               "extruder), 0: speed * bead width * layer height"),
        number("sigma_mm", "mm", ValueRange::closed(0.001, 100.0), process.sigma_mm,
               "standard deviation of the Gaussian footprint", "aerosol"),
        number("shutter_time_s", "s", ValueRange::closed(0.001, 10.0), process.shutter_time_s,
               "time the flap takes to open or close", "aerosol"),
        number("line_width_mm", "mm", ValueRange::closed(0.0, 100.0), process.line_width_mm,
               "the line's width for the target region; 0: 4 sigma (aerosol) or the bead width "
               "(extrusion)"),
        number("bead_width_mm", "mm", ValueRange::closed(0.01, 100.0), process.bead_width_mm,
               "bead width; the nominal flow is the path's print speed * bead width * layer "
               "height",
               "extrusion"),
        number("layer_height_mm", "mm", ValueRange::closed(0.001, 100.0), process.layer_height_mm,
               "bead height", "extrusion"),
        number("tau_s", "s", positive_up_to(100.0), process.tau_s,
               "time constant of the flow's first-order lag behind its command", "extrusion"),
        [&] {
          SchemaKey key = word("retract", {"false", "true"}, process.retract ? "true" : "false",
                               "the extruder may pull the filament back: a flow command below "
                               "0, as pressure advance commands in a deceleration (the nozzle "
                               "flow stops at 0); uniform then decelerates at a_max instead of "
                               "at most |v| / tau_s");
          key.type = "true | false";
          key.applies_to = "extrusion";
          return key;
        }()}});

  // toolpath and its kinds
  schema.push_back(
      {"toolpath",
       "the print paths: speed, start and end, and exactly one of segments, polylines, gcode, "
       "random_segments, surface",
       {number("speed", "mm/s", positive_up_to(ranges::kMaxSpeed_mm_s), 0.0,
               "print speed of every path that gives none"),
        other("start", "point [x, y] or [x, y, z], each in [-1e+06, 1e+06]", "mm", "[0, 0, 0]",
              "where the machine starts, at rest (surface: 20 mm above the part; gcode: the "
              "file's first print point, before offset)"),
        other("end", "point [x, y] or [x, y, z], each in [-1e+06, 1e+06]", "mm", "start",
              "where the machine ends, at rest (gcode: the start raised to the highest print "
              "point read, or the last one where that is out of reach)"),
        other("offset", "point [dx, dy] or [dx, dy, dz], each in [-1e+06, 1e+06]", "mm", "none",
              "added to every point, start and end (not with surface)"),
        other("segments", "list of [[x, y], [x, y]]", "mm", "-",
              "print segments in this order; segments whose ends touch meet at a joint"),
        other("polylines", "list of point lists or {points, speed}", "mm", "-",
              "print polylines; each interior point is a joint"),
        other("gcode", "text or map", "", "-",
              "a G-code file (or {file, rule, ...}, see toolpath.gcode): print moves become "
              "polylines at their feed rate"),
        other("random_segments", "map", "", "-",
              "Ganganath et al.'s random instances (see toolpath.random_segments)"),
        other("surface", "map", "", "-",
              "conformal hatching of an STL part (see toolpath.surface)")}});
  schema.back().keys.front().default_text = "required (segments, polylines without speed:)";
  schema.back().keys.front().default_value = std::nullopt;
  schema.push_back(
      {"toolpath.polylines[]",
       "one polyline: a bare point list, or a map",
       {other("points", "list of points", "mm", "required", "the polyline's points, >= 2"),
        number("speed", "mm/s", positive_up_to(ranges::kMaxSpeed_mm_s), 0.0,
               "this polyline's print speed")}});
  schema.back().keys.back().default_text = "toolpath.speed";
  schema.back().keys.back().default_value = std::nullopt;
  {
    // `gcode: FILE` is `gcode: {file: FILE}` with every default below
    const GcodeToolpath gcode;
    schema.push_back(
        {"toolpath.gcode",
         "a G-code file (RS274/NGC, RepRap/Marlin/Klipper) and how its moves print",
         {other("file", "text", "", "required", "the G-code file, relative to the scenario"),
          word("rule", {"auto", "e", "shutter", "feed"}, gcode.rule,
               "what prints: e (E increases), shutter (G1-G3 while `open` is active and the "
               "modal S, a laser's power, is not 0), feed "
               "(G1-G3 print, G0 travels); auto: e if the file has E, else shutter if it has "
               "the codes, else feed (metrics.json's warnings say which)"),
          other("open", "text", "", gcode.open_code, "the shutter rule's open code (e.g. M106)"),
          other("close", "text", "", gcode.close_code, "the shutter rule's close code (e.g. M107)"),
          other("layers", "[from, to], whole numbers >= 0, from <= to", "", "every layer",
                "the file's layers to print, 0-based, inclusive (layers by increasing z; a "
                "print run's z is that of its first move at one height)"),
          word("feed", {"clamp", "error"}, gcode.feed,
               "feed rates above the machine's limits: clamp slows each move to what every "
               "axis can do along it (as firmware does; metrics.json counts them), error "
               "refuses them"),
          number("chord_tolerance_mm", "mm", ValueRange::closed(1e-4, 1.0),
                 gcode.chord_tolerance_mm,
                 "arcs (G2/G3) become chords whose sagitta is at most this")}});
  }
  {
    SchemaKey speed = number("speed", "mm/s", positive_up_to(ranges::kMaxSpeed_mm_s),
                             random.speed_mm_s, "print speed");
    speed.default_text = "toolpath.speed";
    speed.default_value = std::nullopt;
    schema.push_back(
        {"toolpath.random_segments",
         "n random segments on a bed (Ganganath et al. 2016); its start and end unless given",
         {whole("n", "", 1, 100000, random.count, "number of segments"),
          other("bed", "[w, h], each in (0, 1e+06]", "mm", "required",
                "the bed's size; segments lie inside"),
          other("length", "[min, max], each in (0, 1e+06], min <= max", "mm", "required",
                "segment lengths, uniform in [min, max]"),
          [&] {
            SchemaKey seed = number("seed", "", ValueRange::non_negative(),
                                    static_cast<double>(random.seed), "random seed");
            seed.type = "whole number";
            return seed;
          }(),
          speed}});
  }
  {
    SchemaKey speed = number("speed", "mm/s", positive_up_to(ranges::kMaxSpeed_mm_s), 0.0,
                             "print speed of the hatch");
    speed.default_text = "toolpath.speed";
    speed.default_value = std::nullopt;
    schema.push_back(
        {"toolpath.surface",
         "conformal hatching of a part's top surface (Shembekar et al. 2018, Algorithm 1)",
         {other("file", "text", "", "required", "the part's STL (ASCII or binary)"),
          word("units", {"mm", "cm", "m", "inch", "in"}, "mm", "the STL's unit"),
          other("offset", "point [x, y] (z 0) or [x, y, z], each in [-1e+06, 1e+06]", "mm",
                "[0, 0, 0]", "the part's placement in the work frame, after rotation"),
          other("rotation", "[rx, ry, rz] or one number (about z), each in [-360, 360]", "deg",
                "[0, 0, 0]", "about fixed x, then y, then z, before the offset"),
          number("hatch_mm", "mm", ValueRange::closed(0.01, 100.0), surface.hatch_mm,
                 "line spacing and point spacing of the hatch"),
          other("angles", "list of numbers, each in [-360, 360]", "deg", "[0, 90]",
                "hatch angle of layer k: angles[k % n]"),
          whole("layers", "", 1, 1000, surface.layers, "number of layers"),
          number("layer_height_mm", "mm", positive_up_to(100.0), surface.layer_height_mm,
                 "layer spacing along the offset direction"),
          number("alpha", "", ValueRange::closed(0.0, 1.0), surface.alpha,
                 "tool axis: 0 vertical .. 1 the surface normal"),
          word("layer_offset", {"normal", "z"}, surface.layer_offset,
               "layers offset along the surface normal, or along z (the paper)"),
          number("chord_tolerance_mm", "mm", ValueRange::closed(0.0, 10.0),
                 surface.chord_tolerance_mm,
                 "where the surface rises more than this above the chord between two points "
                 "(a ridge, a step's edge), the point there is added; 0: the grid's points only "
                 "(the paper), else at least 1e-4"),
          speed}});
  }

  // arm
  {
    SchemaKey fixed_roll = number("fixed_roll_deg", "deg", ValueRange::closed(-360.0, 360.0), 0.0,
                                  "with roll: fixed, this roll for the whole job");
    fixed_roll.default_text = "the best fixed roll";
    fixed_roll.default_value = std::nullopt;
    schema.push_back(
        {"arm",
         "arm6 only: the roll about the nozzle axis and the IK branch along the toolpath",
         {word("roll", {"optimized", "fixed"}, arm.optimize_roll ? "optimized" : "fixed",
               "optimized: chosen point by point (a ladder graph); fixed: one roll"),
          fixed_roll,
          whole("branch", "", -1, 7, arm.branch,
                "-1: the best IK branch; 0..7 to force one (bit 0 shoulder back, bit 1 elbow "
                "down, bit 2 wrist flipped)"),
          number("roll_step_deg", "deg", ValueRange::closed(1.0, 90.0), arm.roll_step_deg,
                 "the ladder's roll step; divides 360"),
          number("sample_spacing_mm", "mm", ValueRange::closed(0.1, 1000.0), arm.sample_spacing_mm,
                 "stations along each path (also where the tool turns 5 deg); a longer edge is "
                 "checked at poses this far apart (joints, and a print edge's clearance to the "
                 "part)"),
          number("min_joint_margin_deg", "deg", ValueRange::closed(0.0, 90.0),
                 arm.min_joint_margin_deg, "joints 1-5 at least this far inside their ranges"),
          number("min_wrist_alignment", "", ValueRange{0.0, true, 1.0, false},
                 arm.min_wrist_alignment,
                 "|sin q5| at least this: away from the wrist singularity"),
          number("min_wrist_offset_mm", "mm", ValueRange::closed(0.0, 1000.0),
                 arm.min_wrist_offset_mm,
                 "wrist centre at least this far from the joint-1 axis (shoulder singularity)"),
          number("min_manipulability", "", ValueRange::closed(0.0, 1.0), arm.min_manipulability,
                 "sqrt(det(J J^T)) at least this (linear rows in m)"),
          number(
              "min_clearance_mm", "mm", ValueRange::closed(-100.0, 100.0), arm.min_clearance_mm,
              "links and tool body (not the nozzle's last 3 mm) at least this far from the part"),
          number("max_joint_step_deg", "deg", ValueRange{0.0, false, 180.0, true},
                 arm.max_joint_step_deg,
                 "a larger joint step between neighbouring stations is a jump")}});
  }

  // order
  {
    std::vector<std::string> refinements = refine_methods();
    refinements.push_back("none");
    SchemaKey seed = number("seed", "", ValueRange::non_negative(), static_cast<double>(order.seed),
                            "random seed (method random)");
    seed.type = "whole number";
    schema.push_back({"order",
                      "the print order: a name (method, method+refine, or a refine alone = "
                      "nearest_neighbor+it) or this map",
                      {word("method", sequencer_methods(), order.method,
                            "the sequencer (see `depotwin describe sequencers`)"),
                       word("refine", refinements, "none", "local search after the sequencer"),
                       word("cost_model", cost_models(), order.cost_model,
                            "transition time: machine (synchronised per-axis minimum-time move) or "
                            "along_line (the paper's 1-D model)"),
                       seed}});
  }

  // planners
  schema.push_back(
      {"planners[]",
       "one planner entry: a name, or a map with its parameters (see `depotwin describe "
       "planners`)",
       {other("name", "word", "", "required", "a registered planner"),
        other("label", "text", "", "the planner's name",
              "names the run and its results folder (to run one planner twice)")}});

  // sim and outputs
  schema.push_back(
      {"sim",
       "simulation and deposition-grid settings",
       {number("timestep_s", "s",
               ValueRange::closed(ranges::kMinTimestep_s, ranges::kMaxTimestep_s), sim.timestep_s,
               "MuJoCo's physics step; with kp_scale: kp_scale * (timestep_s / 1 ms)^2 <= " +
                   format_number(ranges::kMaxServoStiffnessPerStep) + " (xy_stage, arm6), " +
                   format_number(ranges::max_servo_stiffness_per_step("cartesian")) +
                   " (cartesian), " +
                   format_number(ranges::max_servo_stiffness_per_step("linear_delta")) +
                   " (linear_delta): the servo loop's stability"),
        number("control_period_s", "s",
               ValueRange::closed(ranges::kMinTimestep_s, ranges::kMaxControlPeriod_s),
               sim.control_period_s,
               "servo update period, a whole multiple of timestep_s (default: the multiple "
               "nearest 1 ms)"),
        number("cell_mm", "mm", ValueRange::closed(0.0, 100.0), sim.cell_mm,
               "deposition grid cell, 0 or between sigma / 64 and sigma of the footprint (sigma: "
               "process.sigma_mm, or bead width / 4); 0: sigma / 4 (aerosol) or bead width / 8 "
               "(extrusion)"),
        number("kp_scale", "", ValueRange::closed(ranges::kMinKpScale, ranges::kMaxKpScale),
               sim.kp_scale, "multiplies the model's servo gains (see timestep_s)"),
        number("settle_s", "s", ValueRange::closed(0.0, ranges::kMaxSettle_s), sim.settle_s,
               "extra simulated time after the trajectory ends"),
        [&] {
          SchemaKey key =
              whole("max_steps", "", 1, ranges::kMaxMaxSteps, static_cast<double>(sim.max_steps),
                    "the most physics steps a run may take ((plan + settle_s) / "
                    "timestep_s); a longer job is refused before it starts");
          key.default_text = "1e+07";
          return key;
        }()}});
  {
    SchemaKey render = word("render", {"true", "false"}, outputs.render ? "true" : "false",
                            "write the scene image and the plots");
    render.type = "true | false";
    schema.push_back(
        {"outputs",
         "whether a run draws its images, and the scene image's size",
         {render, whole("image_width", "px", 16, 2048, outputs.image_width, "scene image width"),
          whole("image_height", "px", 16, 2048, outputs.image_height, "scene image height")}});
  }
  return schema;
}

}  // namespace

std::string schema_markdown_table(const SchemaSection& section) {
  // a cell's text: '|' escaped, names in code spans
  const auto cell = [](const std::string& text) {
    std::string out;
    for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out.empty() ? std::string("-") : out;
  };
  const bool typed = std::any_of(section.keys.begin(), section.keys.end(),
                                 [](const SchemaKey& k) { return !k.applies_to.empty(); });
  std::string out = typed
                        ? "| key | applies to | unit | accepted | default | meaning |\n"
                          "|---|---|---|---|---|---|\n"
                        : "| key | unit | accepted | default | meaning |\n|---|---|---|---|---|\n";
  for (const SchemaKey& k : section.keys) {
    out += "| `" + k.name + "` | ";
    if (typed) out += (k.applies_to.empty() ? "both" : k.applies_to) + " | ";
    out += cell(k.unit) + " | " + cell(k.accepted()) + " | " + cell(k.default_text) + " | " +
           cell(k.meaning) + " |\n";
  }
  return out;
}

const std::vector<SchemaSection>& scenario_schema() {
  static const std::vector<SchemaSection> schema = make_schema();
  return schema;
}

const SchemaSection& schema_section(const std::string& path) {
  for (const SchemaSection& section : scenario_schema())
    if (section.path == path) return section;
  throw std::out_of_range("no schema section '" + path + "'");
}

}  // namespace depotwin
