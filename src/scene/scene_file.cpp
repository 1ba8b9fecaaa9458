#include "sphere_tree_collision/scene/scene_file.hpp"

#include "carried_state.hpp"
#include "world_access.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <tuple>
#include <map>
#include <set>
#include <sstream>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <unistd.h>

namespace stc {
namespace {

constexpr std::int64_t kMaxSceneEntities = 1000000;  // repeats expanded, whole file
// An explicit grid's sides and voxels (before the World's own max_voxels).
constexpr std::int64_t kMaxSceneGridSide = 4096;
constexpr std::int64_t kMaxSceneGridVoxels = 64ll << 20;

void checkKeys(const YAML::Node& node, const std::string& path, const std::set<std::string>& allowed) {
  for (const auto& kv : node) {
    // A key may be any YAML node ({[1]: 2}); as<std::string> would throw a YAML error (found by fuzz_scene).
    if (!kv.first.IsScalar()) throw InputError(path.empty() ? "scene" : path.substr(0, path.size() - 1), "keys must be plain names");
    const std::string key = kv.first.Scalar();
    if (allowed.count(key) == 0) throw InputError(path + key, "unknown key");
  }
}

double readDouble(const YAML::Node& node, const std::string& field) {
  if (!node.IsScalar()) throw InputError(field, "expected a number");
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(field, "expected a number, got '" + node.Scalar() + "'");
  }
}

std::int64_t readInt(const YAML::Node& node, const std::string& field, std::int64_t lo, std::int64_t hi) {
  if (!node.IsScalar()) throw InputError(field, "expected an integer");
  std::int64_t v = 0;
  try {
    v = node.as<std::int64_t>();
  } catch (const YAML::Exception&) {
    throw InputError(field, "expected an integer, got '" + node.Scalar() + "'");
  }
  if (v < lo || v > hi) {
    throw InputError(field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return v;
}

bool readBool(const YAML::Node& node, const std::string& field) {
  try {
    return node.as<bool>();
  } catch (const YAML::Exception&) {
    throw InputError(field, "expected true or false");
  }
}

std::string readString(const YAML::Node& node, const std::string& field) {
  if (!node.IsScalar()) throw InputError(field, "expected a string");
  return node.Scalar();
}

std::vector<double> readNumbers(const YAML::Node& node, const std::string& field, std::size_t n) {
  if (!node.IsSequence() || node.size() != n) {
    throw InputError(field, "expected a list of " + std::to_string(n) + " numbers");
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(readDouble(node[i], field));
  return out;
}

Vec3 readVec3(const YAML::Node& node, const std::string& field) {
  const auto v = readNumbers(node, field, 3);
  return {v[0], v[1], v[2]};
}

Quat fromRpy(double roll, double pitch, double yaw) {
  return Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ()) *
                   Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
                   Eigen::AngleAxisd(roll, Vec3::UnitX()));
}

// {rpy: [r, p, y]} (radians, fixed axes X then Y then Z), {quat: [x, y, z, w]}
// (normalised) or {unit_quat: [x, y, z, w]} (as written: *exact set).
Quat readOrientation(const YAML::Node& node, const std::string& field, bool* exact) {
  if (!node.IsMap() || node.size() != 1) {
    throw InputError(field, "expected {rpy: [roll, pitch, yaw]} or {quat: [x, y, z, w]}");
  }
  if (node["rpy"]) {
    const auto v = readNumbers(node["rpy"], field + ".rpy", 3);
    return fromRpy(v[0], v[1], v[2]);
  }
  if (node["quat"]) {
    const auto v = readNumbers(node["quat"], field + ".quat", 4);
    return Quat(v[3], v[0], v[1], v[2]);  // validated (unit norm) by addRequest
  }
  if (node["unit_quat"]) {  // kept bit for bit (EntitySpec::exact_orientation)
    const auto v = readNumbers(node["unit_quat"], field + ".unit_quat", 4);
    *exact = true;
    return Quat(v[3], v[0], v[1], v[2]);
  }
  throw InputError(field, "expected {rpy: [roll, pitch, yaw]}, {quat: [x, y, z, w]} or {unit_quat: [x, y, z, w]}");
}

// {size: [nx, ny, nz], voxel_size: s, runs: [empty, solid, empty, ...]}:
// the occupancy (x fastest) as alternating run lengths, empty first.
ExplicitGrid readGrid(const YAML::Node& node, const std::string& field) {
  if (!node.IsMap()) throw InputError(field, "expected {size: [nx, ny, nz], voxel_size: s, runs: [...]}");
  checkKeys(node, field + ".", {"size", "voxel_size", "runs"});
  if (!node["size"] || !node["voxel_size"] || !node["runs"]) throw InputError(field, "needs size, voxel_size and runs");
  ExplicitGrid grid;
  if (!node["size"].IsSequence() || node["size"].size() != 3) throw InputError(field + ".size", "expected [nx, ny, nz]");
  grid.nx = static_cast<int>(readInt(node["size"][0], field + ".size", 1, kMaxSceneGridSide));
  grid.ny = static_cast<int>(readInt(node["size"][1], field + ".size", 1, kMaxSceneGridSide));
  grid.nz = static_cast<int>(readInt(node["size"][2], field + ".size", 1, kMaxSceneGridSide));
  const std::int64_t cells = std::int64_t{grid.nx} * grid.ny * grid.nz;
  if (cells > kMaxSceneGridVoxels) {
    throw InputError(field + ".size", "more than " + std::to_string(kMaxSceneGridVoxels) + " voxels");
  }
  grid.voxel_size = readDouble(node["voxel_size"], field + ".voxel_size");
  const YAML::Node runs = node["runs"];
  if (!runs.IsSequence()) throw InputError(field + ".runs", "expected a list of run lengths");
  std::vector<std::int64_t> lengths;
  std::int64_t total = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    lengths.push_back(readInt(runs[i], field + ".runs", 0, cells));
    total += lengths.back();
    if (total > cells) break;
  }
  if (total != cells) {
    throw InputError(field + ".runs", "the runs add up to " + std::to_string(total) + ", not size's " +
                                          std::to_string(cells) + " voxels");
  }
  grid.occupancy.reserve(static_cast<std::size_t>(cells));
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    grid.occupancy.insert(grid.occupancy.end(), static_cast<std::size_t>(lengths[i]), i % 2 == 1 ? 1 : 0);
  }
  return grid;
}

Rgba readColor(const YAML::Node& node, const std::string& field) {
  if (!node.IsSequence() || (node.size() != 3 && node.size() != 4)) {
    throw InputError(field, "expected [r, g, b] or [r, g, b, a] in [0, 1]");
  }
  Rgba c{1.0f, 1.0f, 1.0f, 1.0f};
  for (std::size_t i = 0; i < node.size(); ++i) {
    const double v = readDouble(node[i], field);
    if (!(v >= 0.0 && v <= 1.0)) throw InputError(field, "components must be in [0, 1]");
    c[i] = static_cast<float>(v);
  }
  return c;
}

void parseEntity(const YAML::Node& node, const std::string& path, Scene& scene) {
  if (!node.IsMap()) throw InputError(path, "expected a map");
  const std::string p = path + ".";
  checkKeys(node, p,
            {"name", "preset", "resolution", "voxel_size", "seed", "position", "orientation", "velocity",
             "angular_velocity", "density", "restitution", "friction", "color", "static", "box_mode",
             "repeat", "mesh_resource", "scale", "strength", "rolling_resistance", "up_axis", "closed_faces",
             "grid", "sleep", "id"});
  // Which shape source, and what belongs to it, is validateRequest's to judge
  // when the scene is added: a file, a topic and a service refuse alike.
  EntityRequest r;
  if (node["mesh_resource"]) r.mesh_resource = readString(node["mesh_resource"], p + "mesh_resource");
  if (node["preset"]) r.preset = readString(node["preset"], p + "preset");
  if (node["scale"]) r.mesh_scale = readVec3(node["scale"], p + "scale");
  if (node["up_axis"]) {
    const std::string up_axis = readString(node["up_axis"], p + "up_axis");
    try {
      r.mesh_up_axis = parseColladaUpAxis(up_axis);
    } catch (const InputError& e) {
      throw InputError(p + "up_axis", e.reason());
    }
  }
  if (node["name"]) r.spec.name = readString(node["name"], p + "name");
  if (node["resolution"]) r.preset_params.resolution = static_cast<int>(readInt(node["resolution"], p + "resolution", 0, 4096));
  if (node["voxel_size"]) {
    (node["mesh_resource"] ? r.mesh_voxel_size : r.preset_params.voxel_size) =
        readDouble(node["voxel_size"], p + "voxel_size");
  }
  if (node["seed"]) r.preset_params.seed = static_cast<std::uint32_t>(readInt(node["seed"], p + "seed", 0, 0xffffffffll));
  if (node["position"]) r.spec.pose.position = readVec3(node["position"], p + "position");
  if (node["orientation"]) {
    r.spec.pose.orientation = readOrientation(node["orientation"], p + "orientation", &r.spec.exact_orientation);
  }
  if (node["sleep"]) {  // a saved world's entity (EntitySpec::restored)
    if (node["repeat"]) throw InputError(p + "sleep", "not with repeat");
    r.spec.restored = true;
    r.spec.sleep_group = static_cast<std::uint32_t>(readInt(node["sleep"], p + "sleep", 0, 0xffffffffll));
  }
  if (node["id"]) {  // a saved world's entity keeps its id
    if (node["repeat"]) throw InputError(p + "id", "not with repeat");
    r.spec.id = static_cast<EntityId>(readInt(node["id"], p + "id", 0, kInvalidEntity - 1));
  }
  if (node["grid"]) {
    for (const char* key : {"resolution", "voxel_size", "seed"}) {
      if (node[key]) throw InputError(p + key, "not for a grid (its voxel size is grid.voxel_size)");
    }
    r.grid = readGrid(node["grid"], p + "grid");
  }
  if (node["velocity"]) r.spec.linear_velocity = readVec3(node["velocity"], p + "velocity");
  if (node["angular_velocity"]) r.spec.angular_velocity = readVec3(node["angular_velocity"], p + "angular_velocity");
  if (node["density"]) r.spec.density = readDouble(node["density"], p + "density");
  if (node["restitution"]) r.spec.material.restitution = readDouble(node["restitution"], p + "restitution");
  if (node["friction"]) r.spec.material.friction = readDouble(node["friction"], p + "friction");
  if (node["strength"]) r.spec.material.strength = readDouble(node["strength"], p + "strength");
  if (node["rolling_resistance"]) {
    r.spec.material.rolling_resistance = readDouble(node["rolling_resistance"], p + "rolling_resistance");
  }
  if (node["color"]) r.color = readColor(node["color"], p + "color");
  if (node["static"]) r.spec.is_static = readBool(node["static"], p + "static");
  if (node["closed_faces"]) {
    const YAML::Node faces = node["closed_faces"];
    if (!faces.IsSequence()) throw InputError(p + "closed_faces", "expected a list of faces, e.g. [-z]");
    std::vector<std::string> names;
    for (std::size_t i = 0; i < faces.size(); ++i) names.push_back(readString(faces[i], p + "closed_faces"));
    try {
      r.spec.closed_faces = parseFaces(names);
    } catch (const InputError& e) {
      throw InputError(p + "closed_faces", e.reason());
    }
  }
  if (node["box_mode"]) {
    try {
      r.spec.box_mode = parseBoxMode(readString(node["box_mode"], p + "box_mode"));
    } catch (const InputError& e) {
      throw InputError(p + "box_mode", e.reason());
    }
  }

  if (!node["repeat"]) {
    scene.entities.push_back({path, std::move(r)});
    return;
  }
  const YAML::Node rep = node["repeat"];
  if (!rep.IsMap()) throw InputError(p + "repeat", "expected {count: [nx, ny, nz], spacing: [dx, dy, dz]}");
  checkKeys(rep, p + "repeat.", {"count", "spacing", "seed_step"});
  if (!rep["count"] || !rep["spacing"]) throw InputError(p + "repeat", "needs count and spacing");
  const auto count = readNumbers(rep["count"], p + "repeat.count", 3);
  const Vec3 spacing = readVec3(rep["spacing"], p + "repeat.spacing");
  const std::int64_t seed_step = rep["seed_step"] ? readInt(rep["seed_step"], p + "repeat.seed_step", 0, 1 << 20) : 0;
  std::int64_t total = 1;
  for (double c : count) {
    if (!(c >= 1 && c <= 100000) || c != std::floor(c)) {
      throw InputError(p + "repeat.count", "expected three integers >= 1");
    }
    total *= static_cast<std::int64_t>(c);
  }
  // Over the whole file, not per entry: many large repeats would otherwise exhaust memory.
  if (total + static_cast<std::int64_t>(scene.entities.size()) > kMaxSceneEntities) {
    throw InputError(p + "repeat.count", "the scene would hold more than " + std::to_string(kMaxSceneEntities) + " entities");
  }
  int index = 0;
  for (int k = 0; k < static_cast<int>(count[2]); ++k) {
    for (int j = 0; j < static_cast<int>(count[1]); ++j) {
      for (int i = 0; i < static_cast<int>(count[0]); ++i, ++index) {
        EntityRequest copy = r;
        copy.spec.pose.position += Vec3(i * spacing.x(), j * spacing.y(), k * spacing.z());
        copy.preset_params.seed = r.preset_params.seed + static_cast<std::uint32_t>(seed_step * index);
        if (!r.spec.name.empty()) copy.spec.name = r.spec.name + "_" + std::to_string(index);
        scene.entities.push_back({path + ".repeat[" + std::to_string(index) + "]", std::move(copy)});
      }
    }
  }
}

// addRequest names fields after EntitySpec; a scene file spells them as its keys.
std::string sceneKeyOf(const std::string& field) {
  static const std::map<std::string, std::string> kKeys{
      {"pose.position", "position"},        {"pose.orientation", "orientation"},
      {"linear_velocity", "velocity"},      {"material.restitution", "restitution"},
      {"material.friction", "friction"},    {"dims", "resolution"},
      {"material.strength", "strength"},    {"material.rolling_resistance", "rolling_resistance"}};
  const auto it = kKeys.find(field);
  return it == kKeys.end() ? field : it->second;
}

// contact_state's rows: a list of lists of `width` numbers each, flat.
std::vector<double> readRows(const YAML::Node& node, const std::string& field, std::size_t width) {
  if (!node.IsSequence()) throw InputError(field, "expected a list of rows of " + std::to_string(width) + " numbers");
  std::vector<double> out;
  out.reserve(node.size() * width);
  for (std::size_t k = 0; k < node.size(); ++k) {
    const std::vector<double> row = readNumbers(node[k], field + "[" + std::to_string(k) + "]", width);
    out.insert(out.end(), row.begin(), row.end());
  }
  return out;
}

// A whole number in [0, hi] (read as a double: 17 digits hold it exactly).
std::uint32_t wholeAt(double v, const std::string& field, double hi) {
  if (!(v >= 0.0 && v <= hi && v == std::floor(v))) {
    throw InputError(field, "expected a whole number in [0, " + std::to_string(static_cast<std::int64_t>(hi)) + "]");
  }
  return static_cast<std::uint32_t>(v);
}

// The place of one of the scene's `bodies` entities.
std::uint32_t bodyAt(double v, const std::string& field, std::size_t bodies) {
  if (bodies == 0) throw InputError(field, "no entity to name");
  return wholeAt(v, field, static_cast<double>(bodies - 1));
}

std::int32_t nodeAt(double v, const std::string& field) {
  if (!(v >= -2147483648.0 && v <= 2147483647.0 && v == std::floor(v))) {
    throw InputError(field, "expected a 32-bit integer");
  }
  return static_cast<std::int32_t>(v);
}

bool flagAt(double v, const std::string& field) {
  if (v != 0.0 && v != 1.0) throw InputError(field, "expected 0 or 1");
  return v == 1.0;
}

Vec3 vec3At(const double* v) { return {v[0], v[1], v[2]}; }

// Each entry's points follow the last's: `first` set in turn, the counts
// must add up to the points given.
template <typename Entry, typename FirstCount>
void countPoints(std::vector<Entry>& entries, std::size_t points, const std::string& field, FirstCount fc) {
  std::uint64_t next = 0;
  for (Entry& e : entries) {
    auto [first, count] = fc(e);
    first = static_cast<std::uint32_t>(std::min<std::uint64_t>(next, 0xffffffffu));
    next += count;
  }
  if (next != points) {
    throw InputError(field, "its points add up to " + std::to_string(next) + ", not the " + std::to_string(points) +
                                " given");
  }
}

// Each row of the list `key` of `node` when it is there (rows of `width`
// numbers): row(its numbers, its field "<p><key>[k]").
template <typename Row>
void readEachRow(const YAML::Node& node, const std::string& p, const char* key, std::size_t width, Row row) {
  if (!node[key]) return;
  const std::vector<double> v = readRows(node[key], p + key, width);
  for (std::size_t k = 0; k * width < v.size(); ++k) row(v.data() + k * width, p + key + "[" + std::to_string(k) + "]");
}

// contact_state's broad phase: its bands, each band's endpoints, the boxes
// (one a body) and the pairs in order.
void readBroadPhase(const YAML::Node& node, std::size_t bodies, CarriedState& c) {
  const std::string p = "contact_state.";
  const auto body = [&](double v, const std::string& field) { return bodyAt(v, field, bodies); };
  const std::vector<double> banding = readNumbers(node["banding"], p + "banding", 10);
  for (int a = 0; a < 3; ++a) {
    c.banding.origin[a] = banding[a];
    c.banding.scale[a] = banding[3 + a];
    c.banding.top[a] = banding[6 + a];
  }
  c.banding.chosen_for = wholeAt(banding[9], p + "banding", 4294967295.0);
  const YAML::Node slots = node["slot_order"];
  if (!slots.IsSequence()) throw InputError(p + "slot_order", "expected a list of the entities' places");
  for (std::size_t k = 0; k < slots.size(); ++k) {
    c.banding.slots.push_back(static_cast<EntityId>(readInt(slots[k], p + "slot_order", 0, static_cast<std::int64_t>(bodies) - 1)));
  }
  const YAML::Node lists = node["band_order"];
  if (!lists.IsSequence() || lists.size() != 3) throw InputError(p + "band_order", "expected three lists of bands");
  for (std::size_t a = 0; a < 3; ++a) {
    const std::string field = p + "band_order[" + std::to_string(a) + "]";
    if (!lists[a].IsSequence()) throw InputError(field, "expected a list of bands");
    for (std::size_t b = 0; b < lists[a].size(); ++b) {
      const YAML::Node band = lists[a][b];
      if (!band.IsSequence()) throw InputError(field, "expected each band as a list of endpoints");
      std::vector<std::uint64_t>& order = c.banding.endpoints[a].emplace_back();
      for (std::size_t k = 0; k < band.size(); ++k) {
        order.push_back(static_cast<std::uint64_t>(readInt(band[k], field, 0, 2 * static_cast<std::int64_t>(bodies) - 1)));
      }
    }
  }
  readEachRow(node, p, "boxes", 6, [&](const double* r, const std::string&) {
    c.boxes.push_back({vec3At(r), vec3At(r + 3)});
  });
  if (c.boxes.size() != bodies) throw InputError(p + "boxes", "one a body: " + std::to_string(bodies));
  if (node["broad_pairs"]) {
    const YAML::Node pairs = node["broad_pairs"];
    if (!pairs.IsSequence() || pairs.size() % 2 != 0) throw InputError(p + "broad_pairs", "expected [a, b, a, b, ...]");
    const std::vector<double> v = readNumbers(pairs, p + "broad_pairs", pairs.size());
    for (std::size_t k = 0; k < v.size(); k += 2) {
      c.broad_pairs.push_back({body(v[k], p + "broad_pairs"), body(v[k + 1], p + "broad_pairs")});
    }
  }
}

// contact_state (carriedState, world_access.hpp), `bodies` the scene's entities; the
// World checks what it alone knows (which bodies are awake and movable, the
// pairs of the boxes, the bands' endpoints) when it is put back.
CarriedState readCarried(const YAML::Node& node, std::size_t bodies) {
  const std::string p = "contact_state.";
  if (!node.IsMap()) throw InputError("contact_state", "expected a map");
  checkKeys(node, p, {"next_group", "rest", "banding", "slot_order", "band_order", "boxes", "broad_pairs", "carried",
                      "carried_points", "warm", "warm_points", "breaks"});
  if (!node["next_group"]) throw InputError(p + "next_group", "missing");
  // The broad phase's parts come together, or none (it starts afresh).
  for (const char* key : {"banding", "slot_order", "band_order", "broad_pairs"}) {
    if (!node[key] != !node["boxes"]) throw InputError(p + key, node["boxes"] ? "missing" : "not without boxes");
  }
  const auto body = [&](double v, const std::string& field) { return bodyAt(v, field, bodies); };
  CarriedState c;
  c.next_group = static_cast<std::uint32_t>(readInt(node["next_group"], p + "next_group", 1, 0xffffffffll));
  readEachRow(node, p, "rest", 16, [&](const double* r, const std::string& field) {
    CarriedState::Rest rest;
    rest.body = body(r[0], field + ".body");
    rest.state.moving = flagAt(r[1], field + ".moving");
    rest.state.rest_time = r[2];
    rest.state.age = r[3];
    for (int b = 0; b < 3; ++b) rest.state.balls[b] = Sphere{vec3At(r + 4 + 4 * b), r[7 + 4 * b]};
    c.rest.push_back(rest);
  });
  if (node["boxes"]) readBroadPhase(node, bodies, c);
  readEachRow(node, p, "carried", 14, [&](const double* r, const std::string& field) {
    CarriedState::CarriedEntry e;
    e.a = body(r[0], field + ".a");
    e.b = body(r[1], field + ".b");
    e.entry.b_in_a = vec3At(r + 2);
    e.entry.a_to_b = Quat(r[8], r[5], r[6], r[7]);
    e.entry.tolerance = r[9];
    e.entry.leaf = SpherePair{nodeAt(r[10], field + ".leaf"), nodeAt(r[11], field + ".leaf")};
    e.entry.level = nodeAt(r[12], field + ".level");
    e.entry.count = wholeAt(r[13], field + ".points", 4294967295.0);
    c.carried.push_back(e);
  });
  readEachRow(node, p, "carried_points", 17, [&](const double* r, const std::string& field) {
    PairContactCache::Point pt;
    pt.on_a = vec3At(r);
    pt.on_b = vec3At(r + 3);
    pt.normal = vec3At(r + 6);
    pt.depth = r[9];
    pt.separation = r[10];
    pt.sphere_bound = r[11];
    pt.node_a = nodeAt(r[12], field + ".node_a");
    pt.node_b = nodeAt(r[13], field + ".node_b");
    pt.level = nodeAt(r[14], field + ".level");
    pt.normal_of_b = flagAt(r[15], field + ".normal_of_b");
    pt.resolved = flagAt(r[16], field + ".resolved");
    c.carried_points.push_back(pt);
  });
  countPoints(c.carried, c.carried_points.size(), p + "carried",
              [](CarriedState::CarriedEntry& e) { return std::tie(e.entry.first, e.entry.count); });
  readEachRow(node, p, "warm", 7, [&](const double* r, const std::string& field) {
    CarriedState::Warm w;
    w.a = body(r[0], field + ".a");
    w.b = body(r[1], field + ".b");
    w.held = flagAt(r[2], field + ".held");
    w.manifold.rolling = vec3At(r + 3);
    w.manifold.count = wholeAt(r[6], field + ".points", WarmStartCache::kMaxPoints);
    c.warm.push_back(w);
  });
  readEachRow(node, p, "warm_points", 9, [&](const double* r, const std::string& field) {
    WarmStartCache::Point pt;
    pt.node_a = nodeAt(r[0], field + ".node_a");
    pt.node_b = nodeAt(r[1], field + ".node_b");
    pt.local_a = vec3At(r + 2);
    pt.normal = r[5];
    pt.friction = vec3At(r + 6);
    c.warm_points.push_back(pt);
  });
  countPoints(c.warm, c.warm_points.size(), p + "warm",
              [](CarriedState::Warm& w) { return std::tie(w.manifold.first, w.manifold.count); });
  readEachRow(node, p, "breaks", 7, [&](const double* r, const std::string& field) {
    c.breaks.push_back({body(r[0], field + ".body"), SplitPlane{vec3At(r + 1), vec3At(r + 4)}});
  });
  return c;
}

}  // namespace

namespace {

Scene parseSceneTree(const std::string& yaml_text) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputError("scene", std::string("not valid YAML: ") + e.what());
  }
  if (!root.IsMap()) throw InputError("scene", "expected a map with keys gravity and entities");
  checkKeys(root, "", {"gravity", "entities", "contact_state"});
  Scene scene;
  if (root["gravity"]) scene.gravity = readVec3(root["gravity"], "gravity");
  if (!scene.gravity.allFinite()) throw InputError("gravity", "not finite");
  if (root["entities"]) {
    const YAML::Node list = root["entities"];
    if (!list.IsSequence()) throw InputError("entities", "expected a list");
    for (std::size_t i = 0; i < list.size(); ++i) {
      parseEntity(list[i], "entities[" + std::to_string(i) + "]", scene);
    }
  }
  if (root["contact_state"]) scene.carried = std::make_shared<const CarriedState>(readCarried(root["contact_state"], scene.entities.size()));
  return scene;
}

}  // namespace

Scene parseSceneYaml(const std::string& yaml_text) {
  try {
    return parseSceneTree(yaml_text);
  } catch (const YAML::Exception& e) {  // any the checks above did not foresee: still a bad scene, by name
    throw InputError("scene", std::string("unexpected YAML: ") + e.what());
  }
}

Scene loadSceneYaml(const std::string& path) {
  validateText(path, "scene");
  std::ifstream in(path);
  if (!in) throw InputError("scene", "cannot read file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return parseSceneYaml(text.str());
}

std::vector<EntityId> addScene(World& world, const Scene& scene, const RequestDefaults& defaults,
                               MeshResolver resolve_mesh) {
  if (scene.carried && world.entityCount() != 0) {
    throw InputError("contact_state", "a saved world's: loaded into a world that holds no entity");
  }
  std::vector<EntityId> ids;
  ids.reserve(scene.entities.size());
  for (const SceneEntry& entry : scene.entities) {
    try {
      ids.push_back(addRequest(world, entry.request, defaults, resolve_mesh));
    } catch (const InputError& e) {
      throw InputError(entry.path + "." + sceneKeyOf(e.field()), e.reason());
    }
  }
  if (scene.carried) {
    try {
      restoreCarried(world, *scene.carried);
    } catch (const InputError& e) {
      for (const EntityId id : ids) world.removeEntity(id);
      throw InputError("contact_state." + e.field(), e.reason());
    }
  }
  return ids;
}

const std::string& defaultSceneYaml() {
  // Six presets in two rows, spinning slowly without gravity, far enough
  // apart that each sphere-tree level reads clearly in rviz.
  static const std::string kYaml = R"(
gravity: [0, 0, 0]
entities:
  - {name: cube,   preset: cube,   resolution: 8,  voxel_size: 0.05, position: [-1.2, -0.6, 0.5],
     angular_velocity: [0, 0, 0.3], color: [0.90, 0.45, 0.20, 1.0]}
  - {name: rock,   preset: rock,   resolution: 10, voxel_size: 0.05, seed: 3, position: [0.0, -0.6, 0.5],
     angular_velocity: [0.2, 0, 0.2], color: [0.62, 0.50, 0.38, 1.0]}
  - {name: L,      preset: L,      resolution: 10, voxel_size: 0.05, position: [1.2, -0.6, 0.5],
     orientation: {rpy: [1.2, 0, 0]}, angular_velocity: [0, 0, -0.3], color: [0.25, 0.60, 0.90, 1.0]}
  - {name: ring,   preset: ring,   resolution: 12, voxel_size: 0.05, position: [-1.2, 0.6, 0.5],
     orientation: {rpy: [1.2, 0, 0]}, angular_velocity: [0, 0, 0.3], color: [0.85, 0.75, 0.20, 1.0]}
  - {name: rod,    preset: rod,    resolution: 16, voxel_size: 0.05, position: [0.0, 0.6, 0.5],
     orientation: {rpy: [0, 0.3, 0.6]}, angular_velocity: [0, 0, 0.4], color: [0.50, 0.80, 0.40, 1.0]}
  - {name: sphere, preset: sphere, resolution: 10, voxel_size: 0.05, position: [1.2, 0.6, 0.5],
     color: [0.80, 0.35, 0.60, 1.0]}
)";
  return kYaml;
}

namespace {

// 17 significant digits: every double reads back as the same bits (-0 as -0).
void putNumber(std::string& out, double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  out += buf;
}

void putNumbers(std::string& out, const double* v, std::size_t n) {
  out += '[';
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) out += ", ";
    putNumber(out, v[i]);
  }
  out += ']';
}

void putVec3(std::string& out, const char* key, const Vec3& v) {
  out += ", ";
  out += key;
  out += ": ";
  putNumbers(out, v.data(), 3);
}

void putKeyNumber(std::string& out, const char* key, double v) {
  out += ", ";
  out += key;
  out += ": ";
  putNumber(out, v);
}

// YAML double-quoted (control bytes are refused on input: only \ and " need escaping).
std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + '"';
}

// The shape's recipe (ShapeInfo::recipe), or its voxels as a grid.
void putShape(std::string& out, const ShapeInfo& info) {
  const ShapeRecipe& recipe = info.recipe;
  if (!recipe.preset.empty()) {
    out += "preset: " + recipe.preset + ", resolution: " + std::to_string(recipe.preset_params.resolution);
    putKeyNumber(out, "voxel_size", recipe.preset_params.voxel_size);
    if (recipe.preset == "rock") out += ", seed: " + std::to_string(recipe.preset_params.seed);
    return;
  }
  if (!recipe.mesh_resource.empty()) {
    out += "mesh_resource: " + quoted(recipe.mesh_resource);
    out += ", resolution: " + std::to_string(recipe.preset_params.resolution);
    if (recipe.mesh_voxel_size != 0.0) putKeyNumber(out, "voxel_size", recipe.mesh_voxel_size);
    putVec3(out, "scale", recipe.mesh_scale);
    if (recipe.mesh_up_axis == static_cast<std::uint8_t>(ColladaUpAxis::ToZUp)) out += ", up_axis: z_up";
    return;
  }
  const VoxelShape& v = info.voxels;
  if (v.isSphere() || v.surfaceMargin() != 0.0) {  // never made without a recipe (presets, meshes)
    throw InputError("shape", "shape '" + info.key + "' has no recipe and is not a plain grid");
  }
  out += "grid: {size: [" + std::to_string(v.nx()) + ", " + std::to_string(v.ny()) + ", " + std::to_string(v.nz()) +
         "], voxel_size: ";
  putNumber(out, v.voxelSize());
  out += ", runs: [";
  std::uint8_t value = 0;  // runs alternate, empty first
  std::size_t run = 0;
  bool first = true;
  for (std::uint8_t cell : v.occupancy()) {
    const std::uint8_t solid = cell != 0 ? 1 : 0;
    if (solid != value) {
      out += first ? "" : ", ";
      out += std::to_string(run);
      first = false;
      value = solid;
      run = 0;
    }
    ++run;
  }
  out += (first ? "" : ", ") + std::to_string(run) + "]}";
}

// One row of contact_state: `values` as a flow list, on a line of its own.
void putRow(std::string& out, std::initializer_list<double> values) {
  out += "    - ";
  putNumbers(out, values.begin(), values.size());
  out += '\n';
}

// A list of rows under `key`, or [] when there is none.
template <typename T, typename Row>
void putRows(std::string& out, const char* key, const std::vector<T>& items, Row row) {
  out += "  ";
  out += key;
  out += items.empty() ? ": []\n" : ":\n";
  for (const T& item : items) row(item);
}

double flag(bool b) { return b ? 1.0 : 0.0; }

// contact_state's broad phase: bands, each band's endpoints, boxes, pairs.
void putBroadPhase(std::string& out, const CarriedState& c) {
  const SweepAndPrune::Banding& bands = c.banding;
  out += "  banding: ";
  putNumbers(out, std::initializer_list<double>{bands.origin[0], bands.origin[1], bands.origin[2], bands.scale[0],
                                                bands.scale[1], bands.scale[2], bands.top[0], bands.top[1],
                                                bands.top[2], double(bands.chosen_for)}.begin(), 10);
  out += "\n  slot_order: [";
  for (std::size_t k = 0; k < bands.slots.size(); ++k) out += (k > 0 ? ", " : "") + std::to_string(bands.slots[k]);
  out += "]\n  band_order:\n";
  for (const auto& list : bands.endpoints) {
    out += "    - [";
    for (std::size_t b = 0; b < list.size(); ++b) {
      out += b > 0 ? ", [" : "[";
      for (std::size_t k = 0; k < list[b].size(); ++k) out += (k > 0 ? ", " : "") + std::to_string(list[b][k]);
      out += ']';
    }
    out += "]\n";
  }
  putRows(out, "boxes", c.boxes, [&](const Aabb& box) {
    putRow(out, {box.min.x(), box.min.y(), box.min.z(), box.max.x(), box.max.y(), box.max.z()});
  });
  out += "  broad_pairs: [";
  for (std::size_t k = 0; k < c.broad_pairs.size(); ++k) {
    out += (k > 0 ? ", " : "") + std::to_string(c.broad_pairs[k][0]) + ", " + std::to_string(c.broad_pairs[k][1]);
  }
  out += "]\n";
}

// What the next tick carries over (carriedState, world_access.hpp), in the order the
// schema gives (scene_file.hpp).
void putCarried(std::string& out, const CarriedState& c) {
  out += "contact_state:\n  next_group: " + std::to_string(c.next_group) + '\n';
  putRows(out, "rest", c.rest, [&](const CarriedState::Rest& r) {
    const auto& b = r.state.balls;
    putRow(out, {double(r.body), flag(r.state.moving), r.state.rest_time, r.state.age, b[0].centre.x(),
                 b[0].centre.y(), b[0].centre.z(), b[0].radius, b[1].centre.x(), b[1].centre.y(), b[1].centre.z(),
                 b[1].radius, b[2].centre.x(), b[2].centre.y(), b[2].centre.z(), b[2].radius});
  });
  if (!c.boxes.empty()) putBroadPhase(out, c);
  putRows(out, "carried", c.carried, [&](const CarriedState::CarriedEntry& e) {
    const PairContactCache::Entry& x = e.entry;
    putRow(out, {double(e.a), double(e.b), x.b_in_a.x(), x.b_in_a.y(), x.b_in_a.z(), x.a_to_b.x(), x.a_to_b.y(),
                 x.a_to_b.z(), x.a_to_b.w(), x.tolerance, double(x.leaf.a), double(x.leaf.b), double(x.level),
                 double(x.count)});
  });
  putRows(out, "carried_points", c.carried_points, [&](const PairContactCache::Point& p) {
    putRow(out, {p.on_a.x(), p.on_a.y(), p.on_a.z(), p.on_b.x(), p.on_b.y(), p.on_b.z(), p.normal.x(), p.normal.y(),
                 p.normal.z(), p.depth, p.separation, p.sphere_bound, double(p.node_a), double(p.node_b),
                 double(p.level), flag(p.normal_of_b), flag(p.resolved)});
  });
  putRows(out, "warm", c.warm, [&](const CarriedState::Warm& w) {
    const Vec3& r = w.manifold.rolling;
    putRow(out, {double(w.a), double(w.b), flag(w.held), r.x(), r.y(), r.z(), double(w.manifold.count)});
  });
  putRows(out, "warm_points", c.warm_points, [&](const WarmStartCache::Point& p) {
    putRow(out, {double(p.node_a), double(p.node_b), p.local_a.x(), p.local_a.y(), p.local_a.z(), p.normal,
                 p.friction.x(), p.friction.y(), p.friction.z()});
  });
  // Written only when a break waits (a tick budget ran out): most files have none.
  if (c.breaks.empty()) return;
  putRows(out, "breaks", c.breaks, [&](const CarriedState::Break& b) {
    const SplitPlane& q = b.plane;
    putRow(out, {double(b.body), q.point.x(), q.point.y(), q.point.z(), q.normal.x(), q.normal.y(), q.normal.z()});
  });
}

}  // namespace

std::string writeSceneYaml(const World& world, const ColorOf& color_of) {
  std::string out = "# A saved world (~save; docs/ros_interface.md, Saved worlds): numbers to 17 digits load back bit for bit.\n";
  out += "gravity: ";
  putNumbers(out, world.config().gravity.data(), 3);
  out += "\nentities:";
  if (world.entityCount() == 0) out += " []";
  out += '\n';
  for (std::size_t i = 0; i < world.entityCount(); ++i) {
    const BodyState& body = world.bodies()[i];
    out += "  - {";
    out += "id: " + std::to_string(world.entityIds()[i]) + ", ";
    if (!world.bodyNames()[i].empty()) out += "name: " + world.bodyNames()[i] + ", ";
    putShape(out, world.shape(world.bodyShapes()[i]));
    putVec3(out, "position", body.pose.position);
    const Quat& q = body.pose.orientation;
    const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
    out += ", orientation: {unit_quat: ";
    putNumbers(out, xyzw, 4);
    out += '}';
    putVec3(out, "velocity", body.linear_velocity);
    putVec3(out, "angular_velocity", body.angular_velocity);
    putKeyNumber(out, "density", world.bodyDensities()[i]);
    putKeyNumber(out, "restitution", body.material.restitution);
    putKeyNumber(out, "friction", body.material.friction);
    putKeyNumber(out, "strength", body.material.strength);
    putKeyNumber(out, "rolling_resistance", body.material.rolling_resistance);
    if (color_of) {
      if (const std::optional<Rgba> color = color_of(world.entityIds()[i])) {
        const double rgba[4] = {(*color)[0], (*color)[1], (*color)[2], (*color)[3]};
        out += ", color: ";
        putNumbers(out, rgba, 4);
      }
    }
    out += body.is_static ? ", static: true" : ", static: false";
    out += ", sleep: " + std::to_string(world.sleepGroup(i));
    out += std::string(", box_mode: ") + toString(world.bodyBoxModes()[i]);
    const std::vector<std::string> faces = faceNames(world.closedFaces(i));
    if (!faces.empty()) {
      out += ", closed_faces: [";
      for (std::size_t f = 0; f < faces.size(); ++f) out += (f > 0 ? ", " : "") + faces[f];
      out += ']';
    }
    out += "}\n";
  }
  putCarried(out, carriedState(world));
  return out;
}

void writeFileAtomically(const std::string& path, const std::string& text, const std::string& field) {
  validateText(path, field);
  const std::string temporary = path + ".tmp" + std::to_string(::getpid());
  std::remove(temporary.c_str());  // a crashed save's; "x": never through a link planted in its place
  std::FILE* file = std::fopen(temporary.c_str(), "wbx");
  if (file == nullptr) throw InputError(field, "cannot write '" + path + "': " + std::strerror(errno));
  const bool written = std::fwrite(text.data(), 1, text.size(), file) == text.size();
  const int write_errno = errno;
  const bool synced = std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
  const bool closed = std::fclose(file) == 0;
  if (!written || !synced || !closed) {
    std::remove(temporary.c_str());
    throw InputError(field, "cannot write '" + path + "': " + std::strerror(written ? errno : write_errno));
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(temporary.c_str());
    throw InputError(field, "cannot write '" + path + "': " + std::strerror(rename_errno));
  }
}

}  // namespace stc
