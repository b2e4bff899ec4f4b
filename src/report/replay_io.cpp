#include "report/replay_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/file_io.hpp"

namespace depotwin {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "replay_deposit.bin is written in the machine's byte order, specified little-endian");

namespace {

constexpr int kReplayVersion = 1;
constexpr char kDepositMagic[8] = {'D', 'T', 'R', 'E', 'P', 'L', 'A', 'Y'};
constexpr const char* kFormatName = "depotwin-replay";

// speed-ups a video may use: these times powers of ten
constexpr double kSpeedupSteps[] = {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0};

// binary writer / reader of plain values (little-endian, see the header)
template <class T>
void put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}
template <class T>
void put_all(std::string& out, const std::vector<T>& values) {
  if (!values.empty())
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

class BinaryReader {
 public:
  BinaryReader(const std::string& bytes, std::string path)
      : bytes_(bytes), path_(std::move(path)) {}
  template <class T>
  T get(const char* what) {
    T value;
    take(&value, sizeof value, what);
    return value;
  }
  template <class T>
  std::vector<T> get_all(size_t count, const char* what) {
    // checked against the bytes left before allocating, so a corrupt count cannot
    // allocate more than the file holds
    if (count > (bytes_.size() - offset_) / sizeof(T)) fail(what);
    std::vector<T> values(count);
    if (count > 0) take(values.data(), count * sizeof(T), what);
    return values;
  }
  bool at_end() const { return offset_ == bytes_.size(); }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_, 0, what, "the file is truncated or corrupt");
  }

 private:
  void take(void* target, size_t size, const char* what) {
    if (size > bytes_.size() - offset_) fail(what);
    std::memcpy(target, bytes_.data() + offset_, size);
    offset_ += size;
  }
  const std::string& bytes_;
  std::string path_;
  size_t offset_ = 0;
};

std::string deposit_bytes(const ReplayDeposit& deposit, size_t frames) {
  std::string out;
  out.append(kDepositMagic, sizeof kDepositMagic);
  put<uint32_t>(out, kReplayVersion);
  put<uint32_t>(out, static_cast<uint32_t>(deposit.nx));
  put<uint32_t>(out, static_cast<uint32_t>(deposit.ny));
  put<uint32_t>(out, static_cast<uint32_t>(frames));
  put<uint32_t>(out, static_cast<uint32_t>(deposit.cell.size()));
  put<uint32_t>(out, deposit.surface_z_mm.empty() ? 0u : 1u);
  put_all(out, deposit.surface_z_mm);
  put_all(out, deposit.frame_begin);
  put_all(out, deposit.cell);
  put_all(out, deposit.thickness_um);
  return out;
}

// reads the arrays of replay_deposit.bin into `deposit` (grid already set from the JSON)
void read_deposit_bytes(const std::string& bytes, const std::string& path, size_t frames,
                        ReplayDeposit& deposit) {
  BinaryReader in(bytes, path);
  char magic[8];
  for (char& c : magic) c = in.get<char>("magic");
  if (std::memcmp(magic, kDepositMagic, sizeof magic) != 0)
    throw InputError(path, 0, "magic", "not a depotwin replay deposit file");
  if (const uint32_t version = in.get<uint32_t>("version"); version != kReplayVersion)
    throw InputError(path, 0, "version",
                     "version " + std::to_string(version) + " is not supported (this build reads " +
                         std::to_string(kReplayVersion) + ")");
  const uint32_t nx = in.get<uint32_t>("nx"), ny = in.get<uint32_t>("ny");
  const uint32_t frame_count = in.get<uint32_t>("frames");
  const uint32_t entries = in.get<uint32_t>("entries");
  const uint32_t has_surface = in.get<uint32_t>("has_surface");
  if (static_cast<int>(nx) != deposit.nx || static_cast<int>(ny) != deposit.ny ||
      frame_count != frames)
    throw InputError(path, 0, "nx/ny/frames", "disagree with " + std::string(kReplayJson));
  const size_t cells = static_cast<size_t>(nx) * ny;
  if (has_surface > 1) in.fail("has_surface");
  if (has_surface == 1) deposit.surface_z_mm = in.get_all<float>(cells, "surface_z_mm");
  deposit.frame_begin = in.get_all<uint32_t>(frames + 1, "frame_begin");
  deposit.cell = in.get_all<uint32_t>(entries, "cell");
  deposit.thickness_um = in.get_all<float>(entries, "thickness_um");
  if (!in.at_end()) in.fail("entries");
  // offsets rising from 0 to entries, cells inside the grid
  if (deposit.frame_begin.front() != 0 || deposit.frame_begin.back() != entries ||
      !std::is_sorted(deposit.frame_begin.begin(), deposit.frame_begin.end()))
    in.fail("frame_begin");
  for (const uint32_t cell : deposit.cell)
    if (cell >= cells) in.fail("cell");
}

template <class T>
Json array_of(const std::vector<T>& values) {
  Json array = Json::array();
  for (const T& value : values) array.push_back(value);
  return array;
}

// a key of the replay JSON, with a message naming the file and the key when it is missing or
// of the wrong type
class JsonFields {
 public:
  JsonFields(const Json& root, std::string path) : root_(root), path_(std::move(path)) {}
  const Json& at(const Json& object, const std::string& key, const std::string& dotted) const {
    if (!object.is_object() || !object.contains(key)) throw InputError(path_, 0, dotted, "missing");
    return object.at(key);
  }
  template <class T>
  T value(const Json& object, const std::string& key, const std::string& dotted) const {
    const Json& node = at(object, key, dotted);
    try {
      return node.get<T>();
    } catch (const nlohmann::json::exception&) {
      throw InputError(path_, 0, dotted, "has the wrong type");
    }
  }
  // an array of `count` values (count 0: any length)
  template <class T>
  std::vector<T> array(const Json& object, const std::string& key, size_t count) const {
    const std::vector<T> values = value<std::vector<T>>(object, key, key);
    if (values.size() != count)
      throw InputError(
          path_, 0, key,
          "has " + std::to_string(values.size()) + " entries, expected " + std::to_string(count));
    return values;
  }
  const Json& root() const { return root_; }

 private:
  const Json& root_;
  std::string path_;
};

}  // namespace

double ReplayTiming::time_of(int frame) const {
  if (frame >= frames - 1) return duration_s;
  return std::min(duration_s, frame * speedup / fps);
}

ReplayTiming replay_timing(double duration_s, double max_length_s, double fps) {
  if (!(max_length_s > 0.0) || !std::isfinite(max_length_s))
    throw InputError("--video-length", "must be a positive number of seconds");
  if (!(fps > 0.0) || !std::isfinite(fps))
    throw InputError("--video-fps", "must be a positive number of frames per second");
  ReplayTiming timing;
  timing.duration_s = std::max(0.0, duration_s);
  timing.fps = fps;
  // the smallest listed speed-up whose frames (both ends included) fit in max_length_s; at
  // least the first and the last frame
  auto frames_at = [&](double speedup) {
    return static_cast<int>(std::ceil(timing.duration_s * fps / speedup - 1e-9)) + 1;
  };
  auto fits = [&](double speedup) {
    const int frames = frames_at(speedup);
    return frames <= 2 || frames <= max_length_s * fps + 1e-9;
  };
  timing.speedup = 1.0;
  for (double decade = 1.0; !fits(timing.speedup); decade *= 10.0)
    for (const double step : kSpeedupSteps)
      if (fits(step * decade)) {
        timing.speedup = step * decade;
        break;
      } else {
        timing.speedup = step * decade;
      }
  timing.frames = frames_at(timing.speedup);
  return timing;
}

std::string speedup_text(double speedup) {
  if (speedup <= 1.0) return "real time";
  char text[32];
  std::snprintf(text, sizeof text, "%gx speed-up", speedup);
  return text;
}

void write_replay(const ReplayData& replay, const std::string& directory) {
  const size_t frames = replay.frame_count();
  if (replay.qpos.size() != frames * static_cast<size_t>(replay.nq) ||
      replay.open_fraction.size() != frames || replay.flow_fraction.size() != frames ||
      replay.depositing.size() != frames || replay.path_index.size() != frames ||
      replay.layer.size() != frames || replay.nozzle_mm.size() != frames ||
      replay.deposit.frame_begin.size() != frames + 1)
    throw InternalError("replay: the per-frame arrays disagree in length");

  Json root;
  root["format"] = kFormatName;
  root["version"] = kReplayVersion;
  root["scenario"] = replay.scenario;
  root["run"] = replay.run_label;
  root["machine"] = replay.machine;
  root["process"] = replay.process;
  root["has_shutter"] = replay.has_shutter;
  root["model"] = {{"file", kReplayModel}, {"source", replay.model_source}};
  root["timing"] = {{"duration_s", replay.timing.duration_s},
                    {"fps", replay.timing.fps},
                    {"speedup", replay.timing.speedup},
                    {"frames", replay.timing.frames}};
  const ReplayDeposit& d = replay.deposit;
  root["deposit"] = {{"file", kReplayDeposit},
                     {"origin_x_mm", d.origin_x_mm},
                     {"origin_y_mm", d.origin_y_mm},
                     {"cell_mm", d.cell_mm},
                     {"nx", d.nx},
                     {"ny", d.ny},
                     {"peak_um", d.peak_um},
                     {"entries", d.cell.size()}};
  root["t_s"] = array_of(replay.t_s);
  root["nq"] = replay.nq;
  Json qpos = Json::array();
  for (size_t k = 0; k < frames; ++k)
    qpos.push_back(std::vector<double>(replay.qpos_of(k), replay.qpos_of(k) + replay.nq));
  root["qpos"] = std::move(qpos);
  root["open_fraction"] = array_of(replay.open_fraction);
  root["flow_fraction"] = array_of(replay.flow_fraction);
  root["depositing"] = array_of(replay.depositing);
  root["path_index"] = array_of(replay.path_index);
  root["layer"] = array_of(replay.layer);
  Json nozzle = Json::array();
  for (const Vec3& p : replay.nozzle_mm) nozzle.push_back({p.x(), p.y(), p.z()});
  root["nozzle_mm"] = std::move(nozzle);

  const fs::path dir(directory);
  write_file_atomically((dir / kReplayModel).string(), replay.model_text);
  write_file_atomically((dir / kReplayDeposit).string(), deposit_bytes(replay.deposit, frames));
  write_file_atomically((dir / kReplayJson).string(), root.dump() + "\n");
}

ReplayData read_replay(const std::string& run_directory) {
  const fs::path dir(run_directory);
  if (!fs::is_directory(dir)) throw InputError(run_directory, 0, "RUN_DIR", "is not a folder");
  const std::string json_path = (dir / kReplayJson).string();
  if (!fs::is_regular_file(json_path))
    throw InputError(run_directory, 0, "RUN_DIR",
                     std::string("holds no replay data (") + kReplayJson +
                         "): give a run's folder, e.g. results/<scenario>/<planner>, written by "
                         "`depotwin run` or `compare` of this version");
  Json root;
  try {
    root = Json::parse(read_text_file(json_path));
  } catch (const nlohmann::json::parse_error& error) {
    throw InputError(json_path, 0, "", std::string("not valid JSON: ") + error.what());
  }
  const JsonFields fields(root, json_path);
  if (fields.value<std::string>(root, "format", "format") != kFormatName)
    throw InputError(json_path, 0, "format", std::string("is not ") + kFormatName);
  if (const int version = fields.value<int>(root, "version", "version"); version != kReplayVersion)
    throw InputError(json_path, 0, "version",
                     std::to_string(version) + " is not supported (this build reads " +
                         std::to_string(kReplayVersion) + ")");

  ReplayData replay;
  replay.scenario = fields.value<std::string>(root, "scenario", "scenario");
  replay.run_label = fields.value<std::string>(root, "run", "run");
  replay.machine = fields.value<std::string>(root, "machine", "machine");
  replay.process = fields.value<std::string>(root, "process", "process");
  replay.has_shutter = fields.value<bool>(root, "has_shutter", "has_shutter");
  const Json& model = fields.at(root, "model", "model");
  replay.model_source = fields.value<std::string>(model, "source", "model.source");
  const Json& timing = fields.at(root, "timing", "timing");
  replay.timing.duration_s = fields.value<double>(timing, "duration_s", "timing.duration_s");
  replay.timing.fps = fields.value<double>(timing, "fps", "timing.fps");
  replay.timing.speedup = fields.value<double>(timing, "speedup", "timing.speedup");
  replay.timing.frames = fields.value<int>(timing, "frames", "timing.frames");
  if (replay.timing.frames < 1 || !(replay.timing.fps > 0.0) || !(replay.timing.speedup > 0.0))
    throw InputError(json_path, 0, "timing", "frames, fps and speedup must be positive");

  // the per-frame arrays, one entry per frame
  const size_t frames = static_cast<size_t>(replay.timing.frames);
  replay.t_s = fields.array<double>(root, "t_s", frames);
  replay.nq = fields.value<int>(root, "nq", "nq");
  const std::vector<std::vector<double>> qpos =
      fields.array<std::vector<double>>(root, "qpos", frames);
  for (const std::vector<double>& q : qpos) {
    if (q.size() != static_cast<size_t>(replay.nq))
      throw InputError(json_path, 0, "qpos", "an entry's length is not nq");
    replay.qpos.insert(replay.qpos.end(), q.begin(), q.end());
  }
  replay.open_fraction = fields.array<float>(root, "open_fraction", frames);
  replay.flow_fraction = fields.array<float>(root, "flow_fraction", frames);
  replay.depositing = fields.array<uint8_t>(root, "depositing", frames);
  replay.path_index = fields.array<int>(root, "path_index", frames);
  replay.layer = fields.array<int>(root, "layer", frames);
  for (const std::vector<double>& p :
       fields.array<std::vector<double>>(root, "nozzle_mm", frames)) {
    if (p.size() != 3) throw InputError(json_path, 0, "nozzle_mm", "an entry is not (x, y, z)");
    replay.nozzle_mm.emplace_back(p[0], p[1], p[2]);
  }

  // the deposit grid, then its arrays from the binary file
  const Json& deposit = fields.at(root, "deposit", "deposit");
  ReplayDeposit& d = replay.deposit;
  d.origin_x_mm = fields.value<double>(deposit, "origin_x_mm", "deposit.origin_x_mm");
  d.origin_y_mm = fields.value<double>(deposit, "origin_y_mm", "deposit.origin_y_mm");
  d.cell_mm = fields.value<double>(deposit, "cell_mm", "deposit.cell_mm");
  d.nx = fields.value<int>(deposit, "nx", "deposit.nx");
  d.ny = fields.value<int>(deposit, "ny", "deposit.ny");
  d.peak_um = fields.value<float>(deposit, "peak_um", "deposit.peak_um");
  if (d.nx < 0 || d.ny < 0 || (d.nx > 0 && !(d.cell_mm > 0.0)))
    throw InputError(json_path, 0, "deposit", "the grid's size or cell is not valid");
  const std::string deposit_path = (dir / kReplayDeposit).string();
  read_deposit_bytes(read_text_file(deposit_path), deposit_path, frames, d);
  replay.model_text = read_text_file((dir / kReplayModel).string());
  return replay;
}

DepositPlayback::DepositPlayback(const ReplayDeposit& deposit) : deposit_(deposit) {
  map_.origin_x_mm = deposit.origin_x_mm;
  map_.origin_y_mm = deposit.origin_y_mm;
  map_.cell_mm = deposit.cell_mm;
  map_.nx = deposit.nx;
  map_.ny = deposit.ny;
  map_.thickness_um.assign(static_cast<size_t>(deposit.nx) * deposit.ny, 0.0f);
}

const HeightMap& DepositPlayback::at(size_t frame) {
  const size_t frames = deposit_.frame_begin.empty() ? 0 : deposit_.frame_begin.size() - 1;
  if (frames == 0) return map_;
  frame = std::min(frame, frames - 1);
  // back in time: start again from nothing
  if (frame + 1 < applied_) {
    std::fill(map_.thickness_um.begin(), map_.thickness_um.end(), 0.0f);
    applied_ = 0;
  }
  for (; applied_ <= frame; ++applied_)
    for (uint32_t e = deposit_.frame_begin[applied_]; e < deposit_.frame_begin[applied_ + 1]; ++e)
      map_.thickness_um[deposit_.cell[e]] = deposit_.thickness_um[e];
  return map_;
}

}  // namespace depotwin
