// SPDX-License-Identifier: BSD-3-Clause
// Shards of the localisation experiment and their merge (docs/design/experiment.md,
// "Shards"): shard.json holds the experiment's identity, the shard's range
// and every number of its outcomes as JSON doubles, which read back bit for
// bit, so the merge writes the files of one run. Every field is read with
// its type and range checked, and a refusal names the folder and the field.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/experiment.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss {

namespace {

using nlohmann::json;

constexpr std::size_t kMaxShards = 1000000;
constexpr std::size_t kMaxScans = std::size_t(1) << 32;
constexpr std::size_t kMaxShardFileBytes = std::size_t(1) << 32;
constexpr int kMaxDepth = 8;  // shard.json nests 5 levels

json PoseToJson(const SE3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation().quaternion();
  const Eigen::Vector3d& t = pose.translation();
  return json::array({t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
}

json OutcomeToJson(const ScanOutcome& o) {
  const ScanMatchingResult& r = o.result;
  return {{"scan", o.scan},
          {"time", o.time},
          {"initial", {o.initial_translation_error, o.initial_rotation_error_deg}},
          {"error", {o.translation_error, o.rotation_error_deg}},
          {"pose", PoseToJson(r.pose)},
          {"iterations", r.iterations},
          {"cost", r.final_cost},
          {"n_geo", r.n_geo},
          {"n_rcs", r.n_rcs},
          {"converged", r.converged},
          {"reason", r.reason},
          {"time_ms", r.time_ms}};
}

// Typed reads of one shard.json: "<folder>: shard.json: '<field>' <fault>".
class ShardFields {
 public:
  explicit ShardFields(std::string dir) : dir_(std::move(dir)) {}

  const json& Member(const json& object, const std::string& field, const std::string& key) const {
    if (!object.is_object()) Refuse(field, "must be an object");
    const auto it = object.find(key);
    if (it == object.end()) Refuse(Join(field, key), "is missing");
    return *it;
  }
  std::size_t Whole(const json& v, const std::string& field, std::size_t max) const {
    if (!v.is_number_unsigned() || v.get<std::uint64_t>() > max) {
      Refuse(field, "must be a whole number in [0, " + std::to_string(max) + "]");
    }
    return v.get<std::size_t>();
  }
  double Finite(const json& v, const std::string& field) const {
    if (!v.is_number() || !std::isfinite(v.get<double>())) Refuse(field, "must be a finite number");
    return v.get<double>();
  }
  std::vector<double> Numbers(const json& v, const std::string& field, std::size_t n) const {
    if (!v.is_array() || v.size() != n) Refuse(field, "must be a list of " + std::to_string(n) + " numbers");
    std::vector<double> numbers;
    for (std::size_t i = 0; i < n; ++i) numbers.push_back(Finite(v[i], field + "[" + std::to_string(i) + "]"));
    return numbers;
  }
  const json& List(const json& v, const std::string& field, std::size_t size) const {
    if (!v.is_array() || v.size() != size) Refuse(field, "must be a list of " + std::to_string(size));
    return v;
  }
  std::string Text(const json& v, const std::string& field) const {
    if (!v.is_string()) Refuse(field, "must be a string");
    return v.get<std::string>();
  }
  SE3d Pose(const json& v, const std::string& field) const {
    const std::vector<double> p = Numbers(v, field, 7);
    const Eigen::Quaterniond q(p[6], p[3], p[4], p[5]);
    if (!(std::abs(q.norm() - 1.0) < kTumQuaternionNormTolerance)) Refuse(field, "holds no unit quaternion");
    return SE3d(SO3d::FromUnitQuaternion(q), Eigen::Vector3d(p[0], p[1], p[2]));
  }
  ScanOutcome Outcome(const json& j, const std::string& field) const {
    ScanOutcome o;
    const auto member = [&](const char* key) -> const json& { return Member(j, field, key); };
    o.scan = Whole(member("scan"), Join(field, "scan"), kMaxScans);
    o.time = Finite(member("time"), Join(field, "time"));
    const std::vector<double> initial = Numbers(member("initial"), Join(field, "initial"), 2);
    const std::vector<double> error = Numbers(member("error"), Join(field, "error"), 2);
    o.initial_translation_error = initial[0], o.initial_rotation_error_deg = initial[1];
    o.translation_error = error[0], o.rotation_error_deg = error[1];
    o.result.pose = Pose(member("pose"), Join(field, "pose"));
    o.result.iterations = int(Whole(member("iterations"), Join(field, "iterations"), 1000000));
    o.result.final_cost = Finite(member("cost"), Join(field, "cost"));
    o.result.n_geo = Whole(member("n_geo"), Join(field, "n_geo"), kMaxScans);
    o.result.n_rcs = Whole(member("n_rcs"), Join(field, "n_rcs"), kMaxScans);
    if (!member("converged").is_boolean()) Refuse(Join(field, "converged"), "must be true or false");
    o.result.converged = member("converged").get<bool>();
    o.result.reason = Text(member("reason"), Join(field, "reason"));
    o.result.time_ms = Finite(member("time_ms"), Join(field, "time_ms"));
    return o;
  }
  [[noreturn]] void Refuse(const std::string& field, const std::string& what) const {
    throw FileError(dir_, "shard.json: '" + field + "' " + what);
  }
  static std::string Join(const std::string& field, const std::string& key) {
    return field.empty() ? key : field + "." + key;
  }

 private:
  std::string dir_;
};

// One shard folder's shard.json, parsed with its nesting bounded.
json ReadShardFile(const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / "shard.json").string();
  const std::string bytes = ReadFileBytes(path, "shard file", kMaxShardFileBytes);
  const json::parser_callback_t bounded = [&](int depth, json::parse_event_t, json&) {
    if (depth > kMaxDepth) throw FileError(path, "nested deeper than a shard file");
    return true;
  };
  try {
    return json::parse(bytes, bounded);
  } catch (const json::parse_error& e) {
    throw FileError(path, "not JSON (byte " + std::to_string(e.byte) + ")");
  } catch (const json::out_of_range&) {  // the parser's only other error: a number beyond a double
    throw FileError(path, "not a shard file: a number beyond the range of a double");
  }
}

// A shard's header, checked: its index, count, range and identity.
struct ShardHeader {
  Shard shard;
  std::size_t scans = 0, first = 0, end = 0;
  std::map<std::string, std::string> identity;
};

ShardHeader ReadHeader(const json& file, const ShardFields& f) {
  ShardHeader h;
  h.shard.count = f.Whole(f.Member(file, "", "of"), "of", kMaxShards);
  h.shard.index = f.Whole(f.Member(file, "", "shard"), "shard", kMaxShards);
  if (h.shard.index < 1 || h.shard.index > h.shard.count) f.Refuse("shard", "must be in [1, 'of']");
  h.scans = f.Whole(f.Member(file, "", "scans"), "scans", kMaxScans);
  h.first = f.Whole(f.Member(file, "", "first_scan"), "first_scan", kMaxScans);
  h.end = f.Whole(f.Member(file, "", "end_scan"), "end_scan", kMaxScans);
  if (h.first != h.shard.Begin(h.scans) || h.end != h.shard.End(h.scans)) {
    f.Refuse("first_scan", "and 'end_scan' (" + std::to_string(h.first) + ", " + std::to_string(h.end) +
                               ") are not shard " + std::to_string(h.shard.index) + " of " +
                               std::to_string(h.shard.count) + "'s range of " + std::to_string(h.scans) + " scans");
  }
  const json& identity = f.Member(file, "", "experiment");
  if (!identity.is_object()) f.Refuse("experiment", "must be an object");
  for (const auto& [key, value] : identity.items()) h.identity[key] = f.Text(value, "experiment." + key);
  return h;
}

// The first difference of two identities, or "".
std::string IdentityDifference(const std::map<std::string, std::string>& a,
                               const std::map<std::string, std::string>& b) {
  for (const auto& [key, value] : a) {
    const auto it = b.find(key);
    if (it == b.end()) return "'" + key + "' is '" + value + "' where the other shard has none";
    if (it->second != value) return "'" + key + "' is '" + value + "' against '" + it->second + "'";
  }
  for (const auto& [key, value] : b) {
    if (!a.count(key)) return "'" + key + "' is missing where the other shard has '" + value + "'";
  }
  return {};
}

// The shard's references and outcomes appended to `runs` and `references`.
void AppendShard(const json& file, const ShardHeader& h, const ShardFields& f, std::vector<ConfigurationRun>& runs,
                 std::vector<SE3d>& references) {
  const std::size_t held = h.end - h.first;
  const json& poses = f.List(f.Member(file, "", "references"), "references", held);
  for (std::size_t k = 0; k < held; ++k)
    references.push_back(f.Pose(poses[k], "references[" + std::to_string(k) + "]"));
  const json& shard_runs = f.Member(file, "", "runs");
  if (!shard_runs.is_array() || shard_runs.empty()) f.Refuse("runs", "must be a list of configurations");
  if (runs.empty()) runs.resize(shard_runs.size());
  f.List(shard_runs, "runs", runs.size());
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const std::string field = "runs[" + std::to_string(r) + "]";
    const std::string name = f.Text(f.Member(shard_runs[r], field, "name"), field + ".name");
    const double w_rcs = f.Finite(f.Member(shard_runs[r], field, "w_rcs"), field + ".w_rcs");
    if (runs[r].name.empty()) runs[r].name = name, runs[r].w_rcs = w_rcs;
    if (runs[r].name != name)
      f.Refuse(field + ".name", "is '" + name + "' where the other shards ran '" + runs[r].name + "'");
    const json& outcomes = f.List(f.Member(shard_runs[r], field, "outcomes"), field + ".outcomes", held);
    for (std::size_t k = 0; k < held; ++k) {
      const std::string outcome_field = field + ".outcomes[" + std::to_string(k) + "]";
      runs[r].outcomes.push_back(f.Outcome(outcomes[k], outcome_field));
      if (runs[r].outcomes.back().scan != h.first + k) f.Refuse(outcome_field + ".scan", "is not the range's scan");
    }
  }
}

}  // namespace

Shard ParseShard(const std::string& text) {
  const std::size_t slash = text.find('/');
  Shard shard;
  try {
    if (slash == std::string::npos) throw std::invalid_argument(text);
    std::size_t used = 0;
    shard.index = std::stoul(text.substr(0, slash), &used);
    if (used != slash) throw std::invalid_argument(text);
    shard.count = std::stoul(text.substr(slash + 1), &used);
    if (used != text.size() - slash - 1) throw std::invalid_argument(text);
  } catch (const std::logic_error&) {
    throw std::invalid_argument("shard '" + text + "' is not I/N");
  }
  if (shard.index < 1 || shard.index > shard.count || shard.count > kMaxShards) {
    throw std::invalid_argument("shard '" + text + "' needs 1 <= I <= N <= " + std::to_string(kMaxShards));
  }
  return shard;
}

void WriteShard(const std::string& dir, const Shard& shard, std::size_t total_scans, const ExperimentIdentity& identity,
                const std::vector<ConfigurationRun>& runs, const std::vector<SE3d>& references) {
  json file = {{"shard", shard.index},
               {"of", shard.count},
               {"scans", total_scans},
               {"first_scan", shard.Begin(total_scans)},
               {"end_scan", shard.End(total_scans)}};
  json identity_json = json::object();
  for (const auto& [key, value] : identity) identity_json[key] = value;
  file["experiment"] = identity_json;
  json references_json = json::array();
  for (const SE3d& reference : references) references_json.push_back(PoseToJson(reference));
  file["references"] = references_json;
  json runs_json = json::array();
  for (const ConfigurationRun& run : runs) {
    json outcomes = json::array();
    for (const ScanOutcome& o : run.outcomes) outcomes.push_back(OutcomeToJson(o));
    runs_json.push_back({{"name", run.name}, {"w_rcs", run.w_rcs}, {"outcomes", outcomes}});
  }
  file["runs"] = runs_json;
  WriteFileAtomically((std::filesystem::path(dir) / "shard.json").string(),
                      [&](std::ostream& out) { out << file.dump() << "\n"; });
}

std::vector<ConfigurationRun> MergeShards(const std::vector<std::string>& dirs, std::vector<SE3d>& references) {
  if (dirs.empty()) throw DataError("merge needs the folders of the shards");
  std::vector<json> files;
  std::vector<ShardHeader> headers;
  for (const std::string& dir : dirs) {
    files.push_back(ReadShardFile(dir));
    headers.push_back(ReadHeader(files.back(), ShardFields(dir)));
  }
  const ShardHeader& first = headers.front();
  std::vector<std::size_t> order(first.shard.count, dirs.size());  // the argument of each index
  for (std::size_t s = 0; s < dirs.size(); ++s) {
    const ShardHeader& h = headers[s];
    const std::string difference = IdentityDifference(h.identity, first.identity);
    if (h.shard.count != first.shard.count || h.scans != first.scans || !difference.empty()) {
      throw FileError(dirs[s], "a shard of another experiment than " + dirs.front() + " (" +
                                   (difference.empty() ? "shard " + std::to_string(h.shard.index) + " of " +
                                                             std::to_string(h.shard.count) + " of " +
                                                             std::to_string(h.scans) + " scans"
                                                       : difference) +
                                   ")");
    }
    std::size_t& slot = order[h.shard.index - 1];
    if (slot != dirs.size()) throw FileError(dirs[s], "shard " + std::to_string(h.shard.index) + " given twice");
    slot = s;
  }
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (order[i] == dirs.size()) {
      throw DataError("shard " + std::to_string(i + 1) + " of " + std::to_string(order.size()) + " is missing");
    }
  }
  std::vector<ConfigurationRun> runs;
  references.clear();
  for (const std::size_t s : order) AppendShard(files[s], headers[s], ShardFields(dirs[s]), runs, references);
  for (ConfigurationRun& run : runs) run.Summarise();
  return runs;
}

}  // namespace radargauss
