#include "cli/export_verb.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/interrupt.hpp"
#include "metrics/polyline_distance.hpp"
#include "pipeline/job.hpp"
#include "pipeline/job_check.hpp"
#include "pipeline/models_dir.hpp"
#include "pipeline/step_heartbeat.hpp"
#include "report/output_dir.hpp"
#include "toolpath/gcode.hpp"

#ifndef DEPOTWIN_VERSION
#define DEPOTWIN_VERSION "unknown"
#endif

namespace depotwin {

const char* depotwin_version() {
  return DEPOTWIN_VERSION;
}

namespace {

constexpr double kMinMove_mm = 1e-9;  // shorter displacements are no move (the importer's rule)
constexpr double kMinWrittenMove_mm =
    1e-3;  // a speed run is at least this long (10 digits of 1e-4)

// a number with at most `decimals` decimals, trailing zeros dropped, never "-0"
std::string number_text(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  std::string text = buffer;
  if (text.find('.') != std::string::npos) {
    while (text.back() == '0') text.pop_back();
    if (text.back() == '.') text.pop_back();
  }
  if (text == "-0") text = "0";
  return text;
}

// one piece sampled at the export's period: times (local), positions, speeds, and the
// cumulative commanded volume (extrusion) from the piece's start
struct PieceSamples {
  std::vector<double> t_s;
  std::vector<Vec3> position_mm;
  std::vector<double> speed_mm_s;
  std::vector<double> volume_mm3;
};

PieceSamples sample_piece(const TrajectoryPiece& piece, double period_s,
                          double nominal_flow_mm3_s) {
  PieceSamples samples;
  const double duration_s = piece.t_end_s - piece.t_begin_s;
  const size_t steps = std::max<size_t>(1, static_cast<size_t>(std::ceil(duration_s / period_s)));
  for (size_t k = 0; k <= steps; ++k) {
    const double tau = std::min(duration_s, static_cast<double>(k) * period_s);
    Vec3 position, velocity, acceleration;
    evaluate_motion(piece, tau, position, velocity, acceleration);
    const double flow = evaluate_flow_fraction(piece, tau) * nominal_flow_mm3_s;
    // the commanded volume by the trapezoid rule between samples
    double volume = 0.0;
    if (k > 0)
      volume = samples.volume_mm3.back() +
               0.5 *
                   (flow + evaluate_flow_fraction(piece, samples.t_s.back()) * nominal_flow_mm3_s) *
                   (tau - samples.t_s.back());
    samples.t_s.push_back(tau);
    samples.position_mm.push_back(position);
    samples.speed_mm_s.push_back(velocity.norm());
    samples.volume_mm3.push_back(volume);
  }
  return samples;
}

// Douglas-Peucker over samples [first, last]: the kept indices (first and last included), so
// every sample between two kept ones lies within tolerance of their chord
std::vector<size_t> simplify(const std::vector<Vec3>& points, size_t first, size_t last,
                             double tolerance_mm) {
  std::vector<bool> keep(last - first + 1, false);
  keep.front() = keep.back() = true;
  std::vector<std::pair<size_t, size_t>> stack{{first, last}};
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    double farthest_mm = -1.0;
    size_t farthest = a;
    for (size_t i = a + 1; i < b; ++i) {
      const double d = point_segment_distance(points[i], points[a], points[b]);
      if (d > farthest_mm) farthest_mm = d, farthest = i;
    }
    if (farthest_mm > tolerance_mm) {
      keep[farthest - first] = true;
      stack.push_back({a, farthest});
      stack.push_back({farthest, b});
    }
  }
  std::vector<size_t> kept;
  for (size_t i = first; i <= last; ++i)
    if (keep[i - first]) kept.push_back(i);
  return kept;
}

// A circle in the XY plane through three points at one height (a G17 arc), or nothing when
// they are (nearly) collinear or not level.
struct XyCircle {
  Vec3 centre_mm = Vec3::Zero();
  double radius_mm = 0.0;
};

std::optional<XyCircle> circle_through(const Vec3& a, const Vec3& b, const Vec3& c,
                                       double tolerance_mm) {
  if (std::abs(b.z() - a.z()) > tolerance_mm || std::abs(c.z() - a.z()) > tolerance_mm)
    return std::nullopt;
  // the circumcentre of the triangle in the plane
  const double bx = b.x() - a.x(), by = b.y() - a.y(), cx = c.x() - a.x(), cy = c.y() - a.y();
  const double d = 2.0 * (bx * cy - by * cx);
  const double scale = std::max(bx * bx + by * by, cx * cx + cy * cy);
  if (std::abs(d) <= 1e-12 * scale) return std::nullopt;
  const double ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d;
  const double uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d;
  XyCircle circle;
  circle.centre_mm = Vec3(a.x() + ux, a.y() + uy, a.z());
  circle.radius_mm = std::hypot(ux, uy);
  return circle;
}

// The samples [first, last] as one G2/G3 arc: every sample within tolerance of the circle
// through the first, middle and last sample, level, turning one way through less than a full
// turn. Returns the circle and the signed sweep (rad, positive counter-clockwise: G3).
std::optional<std::pair<XyCircle, double>> fit_arc(const std::vector<Vec3>& points, size_t first,
                                                   size_t last, double tolerance_mm) {
  constexpr double kMaxRadius_mm = 1e4;  // flatter than this is a line to a printer
  if (last < first + 2) return std::nullopt;
  const size_t middle = (first + last) / 2;
  const std::optional<XyCircle> circle =
      circle_through(points[first], points[middle], points[last], tolerance_mm);
  if (!circle || circle->radius_mm > kMaxRadius_mm) return std::nullopt;
  const Vec3& c = circle->centre_mm;
  // the angle turned from sample to sample, all one way
  double sweep = 0.0;
  for (size_t k = first; k <= last; ++k) {
    const Vec3& p = points[k];
    if (std::abs(std::hypot(p.x() - c.x(), p.y() - c.y()) - circle->radius_mm) > tolerance_mm ||
        std::abs(p.z() - points[first].z()) > tolerance_mm)
      return std::nullopt;
    if (k == first) continue;
    const Vec3& q = points[k - 1];
    const double turn =
        std::atan2((q.x() - c.x()) * (p.y() - c.y()) - (q.y() - c.y()) * (p.x() - c.x()),
                   (q.x() - c.x()) * (p.x() - c.x()) + (q.y() - c.y()) * (p.y() - c.y()));
    if (k > first + 1 && (turn > 0.0) != (sweep > 0.0) && std::abs(turn) > 1e-12)
      return std::nullopt;
    sweep += turn;
  }
  if (std::abs(sweep) >= 2.0 * kPi - 1e-6) return std::nullopt;
  return std::make_pair(*circle, sweep);
}

// Positions (and I, J) are written with at least 4 decimals, more where the chord tolerance is
// finer: enough that rounding all three axes moves a point by at most a tenth of it
// (sqrt(3) / 2 10^-d; 4 decimals at 0.00087 mm and above, 9 at most)
int position_decimals(double chord_tolerance_mm) {
  int decimals = 4;
  while (decimals < 9 &&
         0.5 * std::sqrt(3.0) * std::pow(10.0, -decimals) > 0.1 * chord_tolerance_mm)
    ++decimals;
  return decimals;
}

// The G-code lines, with the modal position and feed rate written only when they change.
class GcodeWriter {
 public:
  GcodeWriter(bool extrusion, int position_decimals)
      : extrusion_(extrusion), decimals_(position_decimals) {}

  void line(const std::string& text) { body_ << text << '\n'; }

  // G4 for `seconds` (whole milliseconds), with a comment: "planned pause" or "planned dwell"
  void dwell(double seconds, const char* what) {
    line("G4 P" + number_text(1000.0 * seconds, 0) + " ; planned " + what);
  }

  // G0 or G1 to `to` at `feed_mm_min` (<= 0: no F), with an E increment when e_mm > 0
  void move(const char* code, const Vec3& to, double feed_mm_min, double e_mm) {
    std::string text = code;
    const char* axis_names[3] = {" X", " Y", " Z"};
    for (int axis = 0; axis < 3; ++axis) {
      const std::string value = number_text(to[axis], decimals_);
      if (value != axis_text_[axis]) text += axis_names[axis] + value, axis_text_[axis] = value;
    }
    append_e_and_feed(text, e_mm, feed_mm_min);
    body_ << text << '\n';
  }

  // e_text's value (0: none written)
  double e_written(double e_mm) const {
    const std::string text = e_text(e_mm);
    return text.empty() ? 0.0 : std::stod(text);
  }

  // E as written: at least 3 significant digits (a slow ramp's moves carry very little), up
  // to 10 decimals; "" where that shows no material (e_mm below 5e-11 mm: the move is written
  // without E, a travel to a reader)
  std::string e_text(double e_mm) const {
    if (!extrusion_ || !(e_mm > 0.0)) return "";
    int decimals = 5;
    while (decimals < 10 && e_mm < std::pow(10.0, 2 - decimals)) ++decimals;
    const std::string text = number_text(e_mm, decimals);
    return text.find_first_of("123456789") == std::string::npos ? "" : text;
  }

  // E (e_text) and F when it changes
  void append_e_and_feed(std::string& text, double e_mm, double feed_mm_min) {
    if (const std::string e = e_text(e_mm); !e.empty()) text += " E" + e;
    if (feed_mm_min > 0.0) {
      int decimals = 1;
      while (decimals < 4 && feed_mm_min < std::pow(10.0, 2 - decimals)) ++decimals;
      const std::string feed = number_text(feed_mm_min, decimals);
      if (feed != feed_text_) text += " F" + feed, feed_text_ = feed;
    }
  }

  // G2 (clockwise) or G3 (counter-clockwise) in the XY plane to `to` about `centre` (I and J
  // relative to the start, as G90.1 is not assumed), with F and E as for move()
  void arc(bool counter_clockwise, const Vec3& from, const Vec3& to, const Vec3& centre,
           double feed_mm_min, double e_mm) {
    const std::string i_text = number_text(centre.x() - from.x(), decimals_);
    const std::string j_text = number_text(centre.y() - from.y(), decimals_);
    std::string text = counter_clockwise ? "G3" : "G2";
    const char* axis_names[3] = {" X", " Y", " Z"};
    for (int axis = 0; axis < 3; ++axis) {
      const std::string value = number_text(to[axis], decimals_);
      // an arc's end is always written in the plane, so the reader needs no modal X or Y
      if (axis < 2 || value != axis_text_[axis]) text += axis_names[axis] + value;
      axis_text_[axis] = value;
    }
    text += " I" + i_text + " J" + j_text;
    append_e_and_feed(text, e_mm, feed_mm_min);
    body_ << text << '\n';
  }

  // whether a move to `to` changes the written position (as written)
  bool changes_position(const Vec3& to) const {
    for (int axis = 0; axis < 3; ++axis)
      if (number_text(to[axis], decimals_) != axis_text_[axis]) return true;
    return false;
  }

  std::string text() const { return body_.str(); }

 private:
  bool extrusion_;
  int decimals_;  // of positions, I and J
  std::ostringstream body_;
  std::string axis_text_[3];
  std::string feed_text_;
};

}  // namespace

std::string trajectory_gcode(const Trajectory& trajectory, const GcodeExportJob& job,
                             const GcodeExportSettings& settings) {
  const bool extrusion = job.process == "extrusion";
  const double filament_area_mm2 =
      kPi * 0.25 * settings.filament_diameter_mm * settings.filament_diameter_mm;
  const int decimals = position_decimals(settings.chord_tolerance_mm);
  GcodeWriter gcode(extrusion, decimals);
  size_t print_moves = 0, print_arcs = 0;
  double print_length_mm = 0.0, e_total_mm = 0.0;
  bool open = false;  // aerosol: the shutter code last written
  // extrusion: a move whose E the written digits cannot show (the flow's last trickle at a
  // path's end) is written without E, a travel to a reader, and counted as one; its E goes
  // with the next move that shows E, so the header's counts and E total are the file's. Each
  // written E's rounding goes with the next move too, so the file's E adds up to the plan's
  // (rounded alone, a ramp's 1 ms moves of E0.00124735 written E0.00125 put 0.12 % more
  // into the file than its header said)
  double e_carried_mm = 0.0;
  const auto deposits = [&](double e_mm) {
    return !extrusion || !gcode.e_text(e_mm + e_carried_mm).empty();
  };
  const auto tally = [&](bool prints, double e_mm, double length_mm, bool arc) {
    if (!prints) {
      e_carried_mm += e_mm;
      return;
    }
    const double wanted_mm = e_mm + e_carried_mm;
    const double written_mm = gcode.e_written(wanted_mm);
    e_total_mm += written_mm;
    e_carried_mm = wanted_mm - written_mm;
    ++print_moves;
    print_arcs += arc ? 1 : 0;
    print_length_mm += length_mm;
  };

  // the job's start, at rest
  if (!trajectory.pieces().empty()) {
    Vec3 start, velocity, acceleration;
    evaluate_motion(trajectory.pieces().front(), 0.0, start, velocity, acceleration);
    gcode.move("G0", start, 0.0, 0.0);
  }
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    const double duration_s = piece.t_end_s - piece.t_begin_s;
    if (duration_s <= 0.0) continue;
    const double nominal_flow_mm3_s =
        !extrusion             ? 0.0
        : job.flow_mm3_s > 0.0 ? job.flow_mm3_s
                               : piece.desired_speed_mm_s * job.bead_width_mm * job.layer_height_mm;
    const PieceSamples samples = sample_piece(piece, settings.sample_period_s, nominal_flow_mm3_s);
    const size_t last = samples.t_s.size() - 1;

    // a transition: travels along its planned path within the chord tolerance, each at the
    // feed rate of its planned time (one straight G0 at the planned path's length over its
    // time arrived early: thompson_fig11's uniform file ran 16.25 s of its 17.79; a corner's
    // loop, which ends where it began, was a pause, a stop where the plan keeps moving)
    if (!piece.depositing) {
      if (open) gcode.line(settings.close_code + " ; shutter closed"), open = false;
      double travel_mm = 0.0;
      for (size_t k = 1; k <= last; ++k)
        travel_mm += (samples.position_mm[k] - samples.position_mm[k - 1]).norm();
      if (!(travel_mm > kMinMove_mm)) {
        gcode.dwell(duration_s, "pause");
        continue;
      }
      size_t from = 0;
      for (const size_t to : simplify(samples.position_mm, 0, last, settings.chord_tolerance_mm)) {
        const double length_mm = (samples.position_mm[to] - samples.position_mm[from]).norm();
        if (to == from || !gcode.changes_position(samples.position_mm[to])) continue;
        gcode.move("G0", samples.position_mm[to],
                   60.0 * length_mm / (samples.t_s[to] - samples.t_s[from]), 0.0);
        from = to;
      }
      if (from != last) {
        // (the last points the written digits do not tell apart: the time stands still)
        const double rest_s = samples.t_s[last] - samples.t_s[from];
        if (rest_s >= 0.0005) gcode.dwell(rest_s, "pause");
      }
      continue;
    }
    if (!extrusion && !open) gcode.line(settings.open_code + " ; shutter open"), open = true;

    // runs of nearly constant speed, each simplified within the chord tolerance
    const double band_mm_s =
        settings.speed_tolerance *
        (piece.desired_speed_mm_s > 0.0
             ? piece.desired_speed_mm_s
             : *std::max_element(samples.speed_mm_s.begin(), samples.speed_mm_s.end()));
    size_t written = 0;  // the sample the last written move ended at
    double pending_dwell_s = 0.0;
    size_t run_first = 0;
    while (run_first < last) {
      // a run: the speed within the band, or too short yet to be a move of its own
      size_t run_last = run_first + 1;
      double low = std::min(samples.speed_mm_s[run_first], samples.speed_mm_s[run_last]);
      double high = std::max(samples.speed_mm_s[run_first], samples.speed_mm_s[run_last]);
      while (run_last < last) {
        const double next = samples.speed_mm_s[run_last + 1];
        const bool short_run =
            (samples.position_mm[run_last] - samples.position_mm[run_first]).norm() <
            kMinWrittenMove_mm;
        if (!short_run && std::max(high, next) - std::min(low, next) > band_mm_s) break;
        low = std::min(low, next), high = std::max(high, next), ++run_last;
      }
      const std::vector<size_t> kept =
          simplify(samples.position_mm, run_first, run_last, settings.chord_tolerance_mm);
      for (size_t next = 0; next < kept.size(); ++next) {
        const size_t to = kept[next];
        if (to == written) continue;
        // the longest run of the simplified points from here on that is one arc: a G2/G3
        // (at least three of the lines it replaces, every sample within the tolerance)
        size_t arc_end = next;
        std::optional<std::pair<XyCircle, double>> arc;
        if (next > 0 && written == kept[next - 1]) {
          for (size_t end = next + 2; end < kept.size(); ++end) {
            auto fitted =
                fit_arc(samples.position_mm, written, kept[end], settings.chord_tolerance_mm);
            if (!fitted) break;
            arc = fitted;
            arc_end = end;
          }
        }
        if (arc) {
          const size_t arc_to = kept[arc_end];
          const double length_mm = arc->first.radius_mm * std::abs(arc->second);
          const double move_s = samples.t_s[arc_to] - samples.t_s[written];
          if (pending_dwell_s >= 0.0005) gcode.dwell(pending_dwell_s, "dwell");
          pending_dwell_s = 0.0;
          const double e_mm =
              (samples.volume_mm3[arc_to] - samples.volume_mm3[written]) / filament_area_mm2;
          const bool prints = deposits(e_mm);
          gcode.arc(arc->second > 0.0, samples.position_mm[written], samples.position_mm[arc_to],
                    arc->first.centre_mm, 60.0 * length_mm / move_s,
                    prints ? e_mm + e_carried_mm : 0.0);
          written = arc_to;
          next = arc_end;
          tally(prints, e_mm, length_mm, true);
          continue;
        }
        const double length_mm = (samples.position_mm[to] - samples.position_mm[written]).norm();
        const double move_s = samples.t_s[to] - samples.t_s[written];
        // the nozzle at rest: a dwell; its material goes with the next move
        if (length_mm <= kMinMove_mm) {
          pending_dwell_s += move_s;
          continue;
        }
        // a move the written digits cannot show waits for the next point
        if (!gcode.changes_position(samples.position_mm[to])) continue;
        if (pending_dwell_s >= 0.0005) gcode.dwell(pending_dwell_s, "dwell");
        pending_dwell_s = 0.0;
        const double e_mm =
            (samples.volume_mm3[to] - samples.volume_mm3[written]) / filament_area_mm2;
        const bool prints = deposits(e_mm);
        gcode.move("G1", samples.position_mm[to], 60.0 * length_mm / move_s,
                   prints ? e_mm + e_carried_mm : 0.0);
        written = to;
        tally(prints, e_mm, length_mm, false);
      }
      run_first = run_last;
    }
  }
  if (open) gcode.line(settings.close_code + " ; shutter closed");

  // the header: what was exported, from what, and the conventions
  std::ostringstream header;
  header << kExportedGcodeStart << " " << depotwin_version() << '\n'
         << "; scenario: " << job.scenario_name << " (" << job.scenario_file << ")\n"
         << "; planner: " << job.planner << '\n'
         << "; machine: " << job.machine << '\n';
  if (extrusion)
    header << "; process: extrusion, M83 relative E in mm of "
           << number_text(settings.filament_diameter_mm, 3)
           << " mm filament (E = commanded volume / filament area)\n";
  else
    header << "; process: aerosol, shutter " << settings.open_code << " open / "
           << settings.close_code << " closed\n";
  header << "; planned duration: " << number_text(trajectory.duration_s(), 3) << " s, "
         << print_moves << " print moves (" << print_arcs << " of them G2/G3 arcs), print length "
         << number_text(print_length_mm, 3) << " mm";
  if (extrusion) header << ", E total " << number_text(e_total_mm, 3) << " mm";
  header << '\n'
         << "; every planned sample within "
         << number_text(settings.chord_tolerance_mm, decimals + 1)
         << " mm of these lines and arcs (G2/G3 in the XY plane, I and J relative to the "
            "arc's start), positions rounded to "
         << decimals
         << " decimals (adding at most a tenth of the tolerance); F = each move's planned "
            "average speed\n"
         << "G21 ; millimetres\n"
         << "G90 ; absolute positions\n";
  if (extrusion) header << "M83 ; relative extrusion\n";
  return header.str() + gcode.text() + "; end of job\n";
}

namespace {

// --out must name a file in an existing, writable directory; checked before any planning
void check_out_path(const std::string& out) {
  namespace fs = std::filesystem;
  if (out.empty()) throw InputError("--out", "a G-code file to write is required");
  std::error_code error;
  if (fs::is_directory(out, error))
    throw InputError("--out",
                     "'" + out + "' is a directory; name a file, e.g. " + out + "/job.gcode");
  // a device, link or FIFO would be replaced by the file renamed over it
  if (const std::string problem = replaceable_file_problem(out); !problem.empty())
    throw InputError("--out", problem);
  const fs::path parent =
      fs::path(out).parent_path().empty() ? fs::path(".") : fs::path(out).parent_path();
  if (!fs::is_directory(parent, error))
    throw InputError("--out", "'" + parent.string() + "' is not a directory (for '" + out + "')");
  if (access(parent.c_str(), W_OK) != 0)
    throw InputError("--out", "cannot write in '" + parent.string() + "' (for '" + out + "')");
}

}  // namespace

int export_verb(const ExportOptions& options) {
  check_out_path(options.out);
  const StepHeartbeat heartbeat = job_heartbeat(options.scenario, options.quiet);
  // the shutter codes as inspect and the scenario check them: codes, and not one switch
  for (const ShutterCodeProblem& problem :
       shutter_code_problems(options.settings.open_code, options.settings.close_code))
    throw InputError(problem.at_close ? "--close" : "--open", problem.message);
  // every check before any work (pipeline/job_check.hpp): one run, planned and sampled only
  const Scenario scenario = check_scenario(options.scenario, JobBudget{}, 1, false);
  // never over a file the job reads (its G-code, the scenario itself)
  {
    namespace fs = std::filesystem;
    std::error_code error;
    std::vector<std::string> inputs = scenario_input_files(scenario);
    inputs.insert(inputs.begin(), scenario.file);
    for (const std::string& input : inputs)
      if (fs::equivalent(options.out, input, error))
        throw InputError("--out", "'" + options.out + "' is " +
                                      (input == scenario.file ? "the scenario file"
                                                              : "a file the scenario reads") +
                                      "; name another file to write");
    // nor in the folder of the shipped machine models, which every scenario may read (a
    // built-in machine's MJCF is named by no key of the scenario)
    const fs::path out_folder = fs::absolute(options.out).parent_path();
    if (fs::equivalent(out_folder, models_directory(), error))
      throw InputError("--out", "'" + options.out + "' is in the machine models' folder (" +
                                    models_directory() +
                                    "), which depotwin reads; name a file elsewhere");
  }
  // one writer of the file at a time (report/output_dir.hpp); what writers killed outright
  // left beside it goes
  const std::string target = std::filesystem::absolute(options.out).lexically_normal().string();
  OutputLock lock(target, options.out, "export", !options.no_wait);
  remove_stale_staging(target);
  // 3-axis G-code has no tool axis: a conformal job's tilts would be lost silently
  bool tilted = scenario.surface != nullptr;
  for (const PrintPath& path : scenario.toolpath.paths) tilted = tilted || !path.normals.empty();
  if (tilted)
    throw InputError(scenario.file, scenario.toolpath_line, "toolpath",
                     "export writes 3-axis G-code, which cannot carry the tilted tool axis of a "
                     "conformal toolpath");
  const std::vector<PlannerSpec> planners = select_planners(scenario, options.planner);
  if (planners.size() != 1) {
    std::string labels;
    for (const PlannerSpec& spec : planners)
      labels += (labels.empty() ? "" : ", ") + spec.run_label();
    throw InputError("--planner", "export writes one planner's motion; choose one of " + labels);
  }
  // (every pose of the plan solved, as validate does: G-code the machine cannot follow is
  // refused, not written)
  const PreparedJob job =
      prepare_checked_job(scenario, planners, JobBudget{}, false, false, nullptr, true);
  const WorkingStep step("writing the G-code");
  const PlannedRun planned = plan_job(job, planners.front());

  GcodeExportJob export_job;
  export_job.scenario_name = scenario.name;
  export_job.scenario_file = scenario.file;
  export_job.planner = planners.front().run_label();
  export_job.machine = job.machine->name();
  export_job.process = scenario.process.type;
  export_job.flow_mm3_s = scenario.process.flow_mm3_s;
  export_job.bead_width_mm = scenario.process.bead_width_mm;
  export_job.layer_height_mm = scenario.process.layer_height_mm;
  // a signal that asked to stop leaves the earlier file; the new one is renamed in whole
  const std::string gcode = trajectory_gcode(planned.trajectory, export_job, options.settings);
  throw_if_interrupted();
  write_file_atomically(options.out, gcode);
  lock.release();
  std::cout << "scenario " << scenario.name << ", planner " << export_job.planner << ": "
            << number_text(planned.trajectory.duration_s(), 3) << " s of planned motion written to "
            << options.out << '\n';
  return kExitOk;
}

}  // namespace depotwin
