// SPDX-License-Identifier: BSD-3-Clause
// Map tiles: a map written as tiles reads back byte for byte the same map;
// a neighbourhood read gives exactly the Gaussians and places of the tiles
// within reach, in the map's order; a broken folder gives a clear error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <random>
#include <vector>

#include <nlohmann/json.hpp>

#include "radargauss/core/error.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using MapTiles = testing::TempDirTest;

// Gaussians scattered over 600 m x 300 m (negative coordinates too), every
// third with an RCS model; places every 40 m with a few points.
GaussianMap ScatteredMap() {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> x(-250.0, 350.0), y(-120.0, 180.0), unit(0.0, 1.0);
  GaussianMap map;
  map.incidence = IncidenceModel::kView;
  for (int i = 0; i < 2000; ++i) {
    Gaussian g;
    g.mean = Eigen::Vector3d(x(rng), y(rng), unit(rng));
    g.covariance = Eigen::Vector3d(0.2 + unit(rng), 0.1 + unit(rng), 0.05 + unit(rng)).asDiagonal();
    g.point_count = std::uint32_t(5 + i % 7);
    if (i % 3 == 0) {
      g.rcs.degree = 1;
      g.rcs.median = unit(rng);
      g.rcs.scale = 1.0 + unit(rng);
      for (int j = 0; j < 4; ++j) g.rcs.coefficients[j] = unit(rng) - 0.5;
    }
    map.gaussians.push_back(g);
  }
  for (int p = 0; p < 15; ++p) {
    MapPlace place;
    place.pose = SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, 0.3 * p)), Eigen::Vector3d(-240.0 + 40.0 * p, 10.0, 0.0));
    for (int k = 0; k < 20; ++k) {
      RadarPoint point;
      point.position = Eigen::Vector3d(float(unit(rng) * 30.0), float(unit(rng) * 10.0), 0.0f);
      point.rcs = float(unit(rng) * 10.0);
      place.points.push_back(point);
    }
    map.places.push_back(place);
  }
  return map;
}

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// What a map file holds (place points in float32) comes back from its tiles
// byte for byte.
TEST_F(MapTiles, ReadBackWholeIsTheSameMap) {
  WriteMap(Path("map.rgm"), ScatteredMap());
  const GaussianMap map = ReadMap(Path("map.rgm"));
  WriteMapTiles(Path("tiles"), map, 100.0);
  EXPECT_TRUE(IsMapTiles(Path("tiles")));
  EXPECT_FALSE(IsMapTiles(Path("absent")));
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(Path("tiles")))
    files += entry.path().extension() == ".rgm";
  EXPECT_EQ(files, 7u * 4u);  // x: -300..400, y: -200..200 in 100 m tiles
  const GaussianMap read = ReadMapTiles(Path("tiles"));
  WriteMap(Path("file.rgm"), map);
  WriteMap(Path("read.rgm"), read);
  EXPECT_EQ(Bytes(Path("file.rgm")), Bytes(Path("read.rgm")));
  EXPECT_THROW(WriteMapTiles(Path("tiles"), map, 100.0), DataError);  // not empty
  EXPECT_THROW(WriteMapTiles(Path("other"), map, 0.0), std::invalid_argument);
}

TEST_F(MapTiles, ANeighbourhoodIsTheTilesWithinReach) {
  const GaussianMap map = ScatteredMap();
  const double size = 50.0;
  WriteMapTiles(Path("tiles"), map, size);
  const Eigen::Vector2d center(30.0, 20.0);
  const double radius = 60.0;
  // By hand: a tile is within reach when its square comes within the radius.
  const auto reached = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d low(std::floor(p.x() / size) * size, std::floor(p.y() / size) * size);
    const Eigen::Vector2d nearest = center.cwiseMax(low).cwiseMin(low + Eigen::Vector2d::Constant(size));
    return (nearest - center).norm() <= radius;
  };
  const GaussianMap near = ReadMapTiles(Path("tiles"), center, radius);
  std::vector<Eigen::Vector3d> expected;
  for (const Gaussian& g : map.gaussians) {
    if (reached(g.mean)) expected.push_back(g.mean);
  }
  ASSERT_EQ(near.gaussians.size(), expected.size());
  EXPECT_GT(expected.size(), 100u);
  EXPECT_LT(expected.size(), map.gaussians.size() / 2);
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(near.gaussians[i].mean, expected[i]) << i;
  std::size_t places = 0;
  for (const MapPlace& place : map.places) {
    if (!reached(place.pose.translation())) continue;
    ASSERT_LT(places, near.places.size());
    EXPECT_EQ(near.places[places++].pose.translation(), place.pose.translation());
  }
  EXPECT_EQ(places, near.places.size());
  EXPECT_GT(places, 0u);
  EXPECT_EQ(ReadMapTiles(Path("tiles"), Eigen::Vector2d(1e6, 0.0), 10.0).gaussians.size(), 0u);
}

TEST_F(MapTiles, BrokenFoldersGiveClearErrors) {
  WriteMapTiles(Path("tiles"), ScatteredMap(), 100.0);
  const std::string index_path = Path("tiles/tiles.json");
  const nlohmann::json good = nlohmann::json::parse(Bytes(index_path));
  const auto expect_error = [&](const std::function<void()>& spoil, const std::string& fault) {
    std::ofstream(index_path) << good.dump();
    spoil();
    try {
      ReadMapTiles(Path("tiles"));
      ADD_FAILURE() << "accepted tiles with " << fault;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
  };
  const auto with_index = [&](const std::function<void(nlohmann::json&)>& change) {
    return [&, change] {
      nlohmann::json spoiled = good;
      change(spoiled);
      std::ofstream(index_path) << spoiled.dump();
    };
  };
  expect_error(with_index([](nlohmann::json& j) { j["version"] = 9; }), "version 9");
  expect_error(with_index([](nlohmann::json& j) { j["format"] = "x"; }), "not an index of map tiles");
  expect_error(with_index([](nlohmann::json& j) { j["gaussians"] = 1; }), "do not add up");
  expect_error(with_index([](nlohmann::json& j) { j["tiles"][0]["places"].push_back(0); }), "lists 16 places");
  expect_error(with_index([](nlohmann::json& j) {  // two entries of one place, the count kept
                 std::vector<nlohmann::json*> listed;
                 for (nlohmann::json& tile : j["tiles"]) {
                   for (nlohmann::json& place : tile["places"]) listed.push_back(&place);
                 }
                 *listed[1] = *listed[0];
               }),
               "misplaced");
  expect_error(with_index([](nlohmann::json& j) { j["tiles"][0]["file"] = "../x.rgm"; }), "unexpected");
  expect_error(with_index([](nlohmann::json& j) { j.erase("order"); }), "malformed index");
  expect_error([&] { std::ofstream(index_path) << "{"; }, "malformed index");
  // Counts that lie: each refused before a tile is read, whatever its size.
  const std::size_t first_tile = good["tiles"][0]["gaussians"].get<std::size_t>();
  constexpr std::size_t kMax = std::numeric_limits<std::size_t>::max();
  for (const std::size_t past : {std::size_t(50), std::size_t(1000000)}) {
    expect_error(with_index([&](nlohmann::json& j) {
                   j["order"] = {{0, first_tile + past}, {0, kMax - past + 1}};
                 }),
                 "more Gaussians of tile");
  }
  expect_error(with_index([&](nlohmann::json& j) {
                 j["tiles"][0]["gaussians"] = kMax;
                 j["tiles"][1]["gaussians"] = kMax;
               }),
               "add up past 2^64");
  expect_error(with_index([](nlohmann::json& j) { j["tiles"].push_back(j["tiles"][0]); }), "listed twice");
  // Numbers past 64 bits arrive as doubles: refused by their kind, never converted.
  expect_error(
      [&] {
        std::string text = good.dump();
        const std::size_t order = text.find("\"order\":[[");
        text.insert(order + 10, "184467440737095516152,");
        std::ofstream(index_path) << text;
      },
      "is not a whole number in [0, 2^64)");
  expect_error(with_index([](nlohmann::json& j) { j["tiles"][0]["x"] = 1.5; }), "x or y is not a whole number");
  expect_error(with_index([](nlohmann::json& j) { j["places"] = -1; }), "places is not a whole number");
  expect_error(with_index([](nlohmann::json& j) { j["version"] = 1e30; }), "version");
  expect_error(with_index([](nlohmann::json& j) { j["places"] = 1000000000; }), "places in its tiles for 1000000000");
  expect_error(with_index([&](nlohmann::json& j) { j["places"] = kMax; }), "places in its tiles for");
  expect_error(with_index([](nlohmann::json& j) {
                 for (int k = 0; k < 20000; ++k) {
                   j["tiles"].push_back({{"x", 1000 + k},
                                         {"y", 7},
                                         {"file", "tile_" + std::to_string(1000 + k) + "_7.rgm"},
                                         {"gaussians", 1},
                                         {"places", nlohmann::json::array()}});
                 }
               }),
               "tile_1000_7.rgm: cannot open map tile");
  const std::string tile = Path("tiles/" + good["tiles"][1]["file"].get<std::string>());
  const std::string bytes = Bytes(tile);
  expect_error([&] { std::filesystem::remove(tile); }, tile);
  std::ofstream(tile, std::ios::binary) << bytes;
  std::filesystem::remove(index_path);
  EXPECT_THROW(ReadMapTiles(Path("tiles")), DataError);
}

}  // namespace
}  // namespace radargauss
