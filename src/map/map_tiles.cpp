// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/map_tiles.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using TileKey = std::pair<std::int64_t, std::int64_t>;

constexpr const char* kIndexName = "tiles.json";
constexpr const char* kFormat = "radargauss map tiles";

TileKey TileOf(const Eigen::Vector3d& position, double tile_size) {
  return {FloorToInt(position.x() / tile_size), FloorToInt(position.y() / tile_size)};
}

std::string TileFile(const TileKey& key) {
  return "tile_" + std::to_string(key.first) + "_" + std::to_string(key.second) + ".rgm";
}

// The index as read and checked against itself.
struct TileIndex {
  double tile_size = 0.0;
  IncidenceModel incidence = IncidenceModel::kOffset;
  std::size_t gaussians = 0, places = 0;
  std::vector<TileKey> keys;
  std::vector<std::size_t> tile_gaussians;
  std::vector<std::vector<std::size_t>> tile_places;
  std::vector<std::pair<std::size_t, std::size_t>> order;  // (tile, count) runs
};

// a + b, refused when the sum passes 2^64 (a count of an index that lies).
std::size_t CheckedSum(std::size_t a, std::size_t b, const std::string& path, const std::string& what) {
  if (b > std::numeric_limits<std::size_t>::max() - a) throw FileError(path, what + " add up past 2^64");
  return a + b;
}

// A number of the index as a count or a tile coordinate: a whole number in
// 64 bits. JSON gives a number past them as a double, whose conversion would
// be undefined, so it is refused by its kind before it is read.
std::size_t Count(const Json& value, const std::string& path, const char* what) {
  if (!value.is_number_unsigned()) throw FileError(path, std::string(what) + " is not a whole number in [0, 2^64)");
  return value.get<std::size_t>();
}
std::int64_t Coordinate(const Json& value, const std::string& path) {
  if (!value.is_number_integer()) throw FileError(path, "a tile's x or y is not a whole number in 64 bits");
  return value.get<std::int64_t>();
}

// One entry of "tiles", checked as it is parsed: its file named as its key
// says, listed once, and present (so that a missing tile is named at once).
void TakeTile(const Json& tile, const std::string& dir, const std::string& path, std::set<TileKey>& seen,
              TileIndex& index) {
  const TileKey key(Coordinate(tile.at("x"), path), Coordinate(tile.at("y"), path));
  const std::string file = tile.at("file").get<std::string>();
  if (file != TileFile(key)) throw FileError(path, "tile file '" + Printable(file) + "' unexpected");
  if (!seen.insert(key).second) throw FileError(path, "tile " + file + " listed twice");
  std::error_code error;
  if (!fs::is_regular_file(fs::path(dir) / file, error)) {
    throw FileError((fs::path(dir) / file).string(),
                    "cannot open map tile (listed in " + std::string(kIndexName) + ", no such file)");
  }
  index.keys.push_back(key);
  index.tile_gaussians.push_back(Count(tile.at("gaussians"), path, "a tile's Gaussian count"));
  if (!tile.at("places").is_array()) throw FileError(path, "a tile's places are not a list");
  std::vector<std::size_t> places;
  for (const Json& place : tile.at("places")) places.push_back(Count(place, path, "a tile's place"));
  index.tile_places.push_back(std::move(places));
}

// The index, parsed with memory bounded by its entries (each tile and order
// run is checked and kept as it is read, not held as JSON), and every count
// checked against the others in 64 bits before any tile is read.
TileIndex ReadIndex(const std::string& dir) {
  const std::string path = (fs::path(dir) / kIndexName).string();
  const std::string text = ReadFileBytes(path, "map tiles index");
  TileIndex index;
  try {
    std::set<TileKey> seen;
    std::string key;
    const Json json = Json::parse(text, [&](int depth, Json::parse_event_t event, Json& parsed) {
      if (depth == 1 && event == Json::parse_event_t::key) key = parsed.get<std::string>();
      if (depth != 2) return true;
      if (key == "tiles" && event == Json::parse_event_t::object_end) {
        TakeTile(parsed, dir, path, seen, index);
        return false;
      }
      if (key == "order" && event == Json::parse_event_t::array_end) {
        index.order.emplace_back(Count(parsed.at(0), path, "an order run's tile"),
                                 Count(parsed.at(1), path, "an order run's count"));
        return false;
      }
      return true;
    });
    if (!json.at("tiles").is_array() || !json.at("order").is_array()) throw FileError(path, "malformed index");
    if (json.at("format").get<std::string>() != kFormat) throw FileError(path, "not an index of map tiles");
    if (!json.at("version").is_number_integer() || json.at("version").get<std::int64_t>() != kMapTilesVersion) {
      throw FileError(path, "version " + json.at("version").dump() + " (this build reads " +
                                std::to_string(kMapTilesVersion) + ")");
    }
    index.tile_size = json.at("tile_size").get<double>();
    if (!(index.tile_size > 0.0) || !std::isfinite(index.tile_size)) throw FileError(path, "tile_size not above 0");
    try {
      index.incidence = IncidenceModelFromString(json.at("incidence").get<std::string>());
    } catch (const std::invalid_argument& e) {
      throw FileError(path, e.what());
    }
    index.gaussians = Count(json.at("gaussians"), path, "gaussians");
    index.places = Count(json.at("places"), path, "places");
  } catch (const Json::exception& e) {
    throw FileError(path, std::string("malformed index: ") + e.what());
  }
  // Places: each listed once; their count is that of the entries read, so
  // the check below allocates no more than the index holds.
  std::size_t listed = 0;
  for (const std::vector<std::size_t>& places : index.tile_places)
    listed = CheckedSum(listed, places.size(), path, "places");
  if (listed != index.places) {
    throw FileError(path, "lists " + std::to_string(listed) + " places in its tiles for " +
                              std::to_string(index.places) + " places");
  }
  std::vector<char> place_seen(index.places, 0);
  for (const std::vector<std::size_t>& places : index.tile_places) {
    for (const std::size_t p : places) {
      if (p >= index.places || place_seen[p]++) throw FileError(path, "place " + std::to_string(p) + " misplaced");
    }
  }
  // Gaussians: the tiles' counts add up to the map's, and the order's runs
  // fill each tile exactly, never past its count.
  std::size_t total = 0;
  for (const std::size_t n : index.tile_gaussians) total = CheckedSum(total, n, path, "the tiles' Gaussian counts");
  std::vector<std::size_t> in_runs(index.keys.size(), 0);
  for (const auto& [tile, count] : index.order) {
    if (tile >= index.keys.size() || count == 0) throw FileError(path, "order names no tile");
    if (count > index.tile_gaussians[tile] - in_runs[tile]) {
      throw FileError(path, "order's runs hold more Gaussians of tile " + TileFile(index.keys[tile]) +
                                " than its count " + std::to_string(index.tile_gaussians[tile]));
    }
    in_runs[tile] += count;
  }
  if (total != index.gaussians || in_runs != index.tile_gaussians) {
    throw FileError(path, "the tiles' Gaussian counts do not add up");
  }
  return index;
}

// The map of the chosen tiles (all: every one), Gaussians and places in the map's order.
GaussianMap ReadTiles(const std::string& dir, const TileIndex& index, const std::vector<bool>& chosen) {
  std::vector<GaussianMap> tiles(index.keys.size());
  GaussianMap map;
  map.incidence = index.incidence;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    if (!chosen[t]) continue;
    const std::string path = (fs::path(dir) / TileFile(index.keys[t])).string();
    tiles[t] = ReadMap(path);
    if (tiles[t].gaussians.size() != index.tile_gaussians[t] || tiles[t].places.size() != index.tile_places[t].size()) {
      throw FileError(path, "holds other counts than " + std::string(kIndexName) + " says");
    }
    if (tiles[t].incidence != map.incidence) throw FileError(path, "another incidence model than the index's");
  }
  std::vector<std::size_t> next(tiles.size(), 0);
  for (const auto& [tile, count] : index.order) {
    if (chosen[tile]) {
      const auto begin = tiles[tile].gaussians.begin() + std::ptrdiff_t(next[tile]);
      map.gaussians.insert(map.gaussians.end(), begin, begin + std::ptrdiff_t(count));
    }
    next[tile] += count;
  }
  std::vector<std::pair<std::size_t, MapPlace*>> places;  // by their index in the map
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    if (!chosen[t]) continue;
    for (std::size_t k = 0; k < index.tile_places[t].size(); ++k) {
      places.emplace_back(index.tile_places[t][k], &tiles[t].places[k]);
    }
  }
  std::sort(places.begin(), places.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& place : places) map.places.push_back(std::move(*place.second));
  return map;
}

}  // namespace

void WriteMapTiles(const std::string& dir, const GaussianMap& map, double tile_size) {
  if (!(tile_size > 0.0) || !std::isfinite(tile_size)) throw std::invalid_argument("tile_size must be above 0");
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw FileError(dir, "cannot create the folder of map tiles: " + error.message());
  if (!fs::is_empty(dir, error)) throw FileError(dir, "the folder of map tiles must be empty");
  std::map<TileKey, GaussianMap> tiles;
  std::map<TileKey, std::vector<std::size_t>> tile_places;
  std::vector<TileKey> gaussian_tiles;
  for (const Gaussian& g : map.gaussians) {
    gaussian_tiles.push_back(TileOf(g.mean, tile_size));
    tiles[gaussian_tiles.back()].gaussians.push_back(g);
  }
  for (std::size_t p = 0; p < map.places.size(); ++p) {
    const TileKey key = TileOf(map.places[p].pose.translation(), tile_size);
    tiles[key].places.push_back(map.places[p]);
    tile_places[key].push_back(p);
  }
  Json index = {{"format", kFormat},
                {"version", kMapTilesVersion},
                {"tile_size", tile_size},
                {"incidence", ToString(map.incidence)},
                {"gaussians", map.gaussians.size()},
                {"places", map.places.size()},
                {"tiles", Json::array()},
                {"order", Json::array()}};
  std::map<TileKey, std::size_t> number;
  for (auto& [key, tile] : tiles) {
    tile.incidence = map.incidence;
    number[key] = number.size();
    WriteMap((fs::path(dir) / TileFile(key)).string(), tile);
    index["tiles"].push_back({{"x", key.first},
                              {"y", key.second},
                              {"file", TileFile(key)},
                              {"gaussians", tile.gaussians.size()},
                              {"places", tile_places[key]}});
  }
  for (std::size_t i = 0; i < gaussian_tiles.size();) {
    std::size_t j = i;
    while (j < gaussian_tiles.size() && gaussian_tiles[j] == gaussian_tiles[i]) ++j;
    index["order"].push_back({number[gaussian_tiles[i]], j - i});
    i = j;
  }
  WriteFileAtomically((fs::path(dir) / kIndexName).string(), [&](std::ostream& out) { out << index.dump() << "\n"; });
}

bool IsMapTiles(const std::string& path) {
  std::error_code error;
  return fs::is_directory(path, error) && fs::exists(fs::path(path) / kIndexName, error);
}

GaussianMap ReadMapTiles(const std::string& dir) {
  const TileIndex index = ReadIndex(dir);
  return ReadTiles(dir, index, std::vector<bool>(index.keys.size(), true));
}

GaussianMap ReadMapOrTiles(const std::string& path) { return IsMapTiles(path) ? ReadMapTiles(path) : ReadMap(path); }

GaussianMap ReadMapTiles(const std::string& dir, const Eigen::Vector2d& center, double radius) {
  const TileIndex index = ReadIndex(dir);
  std::vector<bool> chosen(index.keys.size(), false);
  for (std::size_t t = 0; t < index.keys.size(); ++t) {
    // The tile's square against the disc: the nearest point of the square within the radius.
    const Eigen::Vector2d low(double(index.keys[t].first) * index.tile_size,
                              double(index.keys[t].second) * index.tile_size);
    const Eigen::Vector2d nearest = center.cwiseMax(low).cwiseMin(low + Eigen::Vector2d::Constant(index.tile_size));
    chosen[t] = (nearest - center).norm() <= radius;
  }
  return ReadTiles(dir, index, chosen);
}

}  // namespace radargauss
