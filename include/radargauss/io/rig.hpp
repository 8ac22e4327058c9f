// SPDX-License-Identifier: BSD-3-Clause
// A rig file: the radars of one body, each with its scans, its mounting
// T_body_radar and its clock offset (docs/design/rig.md, "The rig file").
//
//   bag: drive.mcap                 # optional: the radars' topics are in it
//   radars:
//     - name: front
//       topic: /front/points        # with bag:, or sequence: FOLDER of scans
//       extrinsic: [3.7, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0]   # x y z qx qy qz qw
//       clock_offset: 0.0           # s: the radar's stamps minus the body's clock
//     - name: rear_left
//       topic: /rear_left/points
//       rotation: [[-0.707, -0.707, 0], [0.707, -0.707, 0], [0, 0, 1]]
//       translation: [-0.9, 0.9, 0.6]
//
// Paths are relative to the rig file. The radars' scans come in one time
// order on the body's clock (ForEachRigScan).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "radargauss/core/types.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

struct RigRadar {
  std::string name;
  SequenceOptions scans;      // sequence_dir, or bag and topic (ground_truth unused)
  SE3d body_from_radar;       // T_body_radar
  double clock_offset = 0.0;  // s: the radar's stamps minus the body's clock (as the IMU's t_d)
};

struct Rig {
  std::vector<RigRadar> radars;
};

// Bounds a rig file is held to: radars and an offset's size.
constexpr std::size_t kMaxRigRadars = 16;
constexpr double kMaxRigClockOffset = 1.0;  // s

// Throws DataError naming the file and the radar for: no radars, a radar
// without scans or with two sources, a topic without a bag, two radars on
// one topic or folder, a name given twice or missing, an extrinsic that is
// not a rotation (a quaternion off unit length by more than 1e-6, a matrix
// off orthonormal by more than 1e-6 or a reflection) or not finite, a
// translation past kMaxLeverArm, an offset past kMaxRigClockOffset, an
// unknown key.
Rig ReadRig(const std::string& path);
// Writes `rig` as ReadRig reads it (extrinsics as x y z qx qy qz qw; paths
// as given), whole or not at all.
void WriteRig(const std::string& path, const Rig& rig);

// Each radar's sequence, and each radar's scans, as read (stamps on the
// radar's own clock). Throws DataError as LoadSequence does, naming the radar.
std::vector<Sequence> LoadRigSequences(const Rig& rig);
std::vector<std::vector<RadarScan>> LoadRigScans(const Rig& rig);

// Every radar's scans in one time order on the body's clock (each scan's
// timestamp minus its radar's clock offset; a tie goes to the radar
// listed first): `visit(radar, scan, source)`. The radars' scans are read
// whole, radar by radar, before the first visit. Throws DataError as
// LoadSequence does, naming the radar.
void ForEachRigScan(const Rig& rig,
                    const std::function<void(std::size_t radar, RadarScan& scan, const std::string& source)>& visit);

}  // namespace radargauss
