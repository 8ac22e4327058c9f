// SPDX-License-Identifier: BSD-3-Clause
// The simulation config's keys read from a YAML map, shared by the readers
// of one radar's config and of a rig's (src/simulator only).
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "radargauss/simulator/simulator.hpp"

namespace radargauss {

// The keys of the map `root` set on `config` (FileError naming `path` for an
// unknown key, a wrong type or a value out of range); a key in `refused` is
// an error saying `why`.
void ApplySimulationKeys(const YAML::Node& root, const std::string& path, SimulationConfig& config,
                         const std::vector<std::string>& refused, const std::string& why);

}  // namespace radargauss
