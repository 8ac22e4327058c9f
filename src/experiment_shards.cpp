// SPDX-License-Identifier: BSD-3-Clause
// Shards of the localisation experiment and their merge (docs/design.md,
// "Shards"): shard.json holds every number of a shard's outcomes as JSON
// doubles, which read back bit for bit, so the merge writes the files of
// one run.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "radargauss/atomic_file.hpp"
#include "radargauss/error.hpp"
#include "radargauss/experiment.hpp"
#include "radargauss/io/read_file.hpp"

namespace radargauss {

namespace {

using nlohmann::json;

json PoseToJson(const SE3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation().quaternion();
  const Eigen::Vector3d& t = pose.translation();
  return json::array({t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
}

SE3d PoseFromJson(const json& v) {
  const Eigen::Quaterniond q(v.at(6).get<double>(), v.at(3).get<double>(), v.at(4).get<double>(),
                             v.at(5).get<double>());
  return SE3d(SO3d::FromUnitQuaternion(q), Eigen::Vector3d(v.at(0).get<double>(), v.at(1).get<double>(),
                                                             v.at(2).get<double>()));
}

json OutcomeToJson(const ScanOutcome& o) {
  const ScanMatchingResult& r = o.result;
  return {{"scan", o.scan}, {"time", o.time}, {"initial", {o.initial_translation_error, o.initial_rotation_error_deg}},
          {"error", {o.translation_error, o.rotation_error_deg}}, {"pose", PoseToJson(r.pose)},
          {"iterations", r.iterations}, {"cost", r.final_cost}, {"n_geo", r.n_geo}, {"n_rcs", r.n_rcs},
          {"converged", r.converged}, {"reason", r.reason}, {"time_ms", r.time_ms}};
}

ScanOutcome OutcomeFromJson(const json& j) {
  ScanOutcome o;
  o.scan = j.at("scan").get<std::size_t>();
  o.time = j.at("time").get<double>();
  o.initial_translation_error = j.at("initial").at(0).get<double>();
  o.initial_rotation_error_deg = j.at("initial").at(1).get<double>();
  o.translation_error = j.at("error").at(0).get<double>();
  o.rotation_error_deg = j.at("error").at(1).get<double>();
  o.result.pose = PoseFromJson(j.at("pose"));
  o.result.iterations = j.at("iterations").get<int>();
  o.result.final_cost = j.at("cost").get<double>();
  o.result.n_geo = j.at("n_geo").get<std::size_t>();
  o.result.n_rcs = j.at("n_rcs").get<std::size_t>();
  o.result.converged = j.at("converged").get<bool>();
  o.result.reason = j.at("reason").get<std::string>();
  o.result.time_ms = j.at("time_ms").get<double>();
  return o;
}

// One shard folder's shard.json, checked against the first shard read.
json ReadShardFile(const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / "shard.json").string();
  try {
    return json::parse(ReadFileBytes(path, "shard file"));
  } catch (const json::exception& e) {
    throw FileError(path, std::string("not a shard file: ") + e.what());
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
  if (shard.index < 1 || shard.index > shard.count) {
    throw std::invalid_argument("shard '" + text + "' needs 1 <= I <= N");
  }
  return shard;
}

void WriteShard(const std::string& dir, const Shard& shard, std::size_t total_scans,
                const std::vector<ConfigurationRun>& runs, const std::vector<SE3d>& references) {
  json file = {{"shard", shard.index}, {"of", shard.count}, {"scans", total_scans},
               {"first_scan", shard.Begin(total_scans)}, {"end_scan", shard.End(total_scans)}};
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
  std::vector<json> shards;
  for (const std::string& dir : dirs) shards.push_back(ReadShardFile(dir));
  const std::size_t count = shards.front().value("of", std::size_t(0));
  const std::size_t total = shards.front().value("scans", std::size_t(0));
  std::vector<int> seen(count + 1, 0);
  for (std::size_t s = 0; s < shards.size(); ++s) {
    const std::size_t index = shards[s].value("shard", std::size_t(0));
    if (shards[s].value("of", std::size_t(0)) != count || shards[s].value("scans", std::size_t(0)) != total ||
        index < 1 || index > count) {
      throw FileError(dirs[s], "a shard of another experiment (shard " + std::to_string(index) + " of " +
                                   std::to_string(shards[s].value("of", 0)) + ")");
    }
    if (seen[index]++) throw FileError(dirs[s], "shard " + std::to_string(index) + " given twice");
  }
  for (std::size_t i = 1; i <= count; ++i) {
    if (!seen[i]) throw DataError("shard " + std::to_string(i) + " of " + std::to_string(count) + " is missing");
  }
  std::sort(shards.begin(), shards.end(), [](const json& a, const json& b) { return a["shard"] < b["shard"]; });
  std::vector<ConfigurationRun> runs;
  references.clear();
  for (const json& shard : shards) {
    for (const json& reference : shard.at("references")) references.push_back(PoseFromJson(reference));
    const json& shard_runs = shard.at("runs");
    if (runs.empty()) runs.resize(shard_runs.size());
    if (shard_runs.size() != runs.size()) throw DataError("the shards ran different configurations");
    for (std::size_t r = 0; r < runs.size(); ++r) {
      const std::string name = shard_runs[r].at("name").get<std::string>();
      if (runs[r].name.empty()) {
        runs[r].name = name;
        runs[r].w_rcs = shard_runs[r].at("w_rcs").get<double>();
      }
      if (runs[r].name != name) throw DataError("the shards ran different configurations ('" + name + "')");
      for (const json& o : shard_runs[r].at("outcomes")) runs[r].outcomes.push_back(OutcomeFromJson(o));
    }
  }
  if (references.size() != total) throw DataError("the shards hold " + std::to_string(references.size()) +
                                                  " scans of " + std::to_string(total));
  for (ConfigurationRun& run : runs) run.Summarise();
  return runs;
}

}  // namespace radargauss
