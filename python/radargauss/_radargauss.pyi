# SPDX-License-Identifier: BSD-3-Clause
# Type stubs of radargauss._radargauss, written by scripts/generate_stubs.py.
from typing import Any, Sequence, TypedDict, Unpack

import numpy
from numpy.typing import ArrayLike

class MatchOptions(TypedDict, total=False):
    """option_fields("match")"""
    solver: str  # 'gn'
    w_rcs: float  # 0.0
    loss: str  # 'trivial'
    loss_scale: float  # 1.0
    rcs_loss: str  # 'cauchy'
    rcs_loss_scale: float  # 1.0
    rcs_likelihood: str  # 'decibel'
    rcs_confidence: bool  # False
    rcs_expected_spread: float  # 0.0
    rcs_translation: str  # 'rotation-only'
    jacobians: str  # 'analytic'
    gate: float  # 3.0
    max_iterations: int  # 30
    coarse_iterations: int  # 15
    coarse_voxel_per_sigma: float  # 2.0
    coarse_points: int  # 0
    geometric_first: bool  # True
    reassociate: bool  # True
    reassociation_translation: float  # 0.01
    reassociation_rotation: float  # 0.002
    translation_tolerance: float  # 0.001
    rotation_tolerance: float  # 0.0001
    coarse_translation_tolerance: float  # 0.01
    coarse_rotation_tolerance: float  # 0.001
    pose_covariance: bool  # False
    gn_max_step_halvings: int  # 8
    gn_loss_curvature: bool  # False
    ceres_dogleg: bool  # False
    ceres_max_inner_iterations: int  # 2
    ceres_max_exact_inner_iterations: int  # 8
    ceres_blocks: str  # 'square-root'
    ceres_threads: int  # 1
    ceres_function_tolerance: float  # 1e-06
    ceres_gradient_tolerance: float  # 1e-10
    ceres_parameter_tolerance: float  # 1e-08
    mh_starts: int  # 8
    mh_xy_offset: float  # 1.0
    mh_yaw_offset: float  # 0.05

class OdometryOptions(MatchOptions, total=False):
    """option_fields("odometry")"""
    mounting: Sequence[float]  # [0.0, 0.0, 0.0]
    velocity_weight: float  # 1.0
    velocity_floor: float  # 0.05
    velocity_vertical_floor: float  # 0.0
    rotation_weight: float  # 1.0
    rotation_rate_std: Sequence[float]  # [1.0, 1.0, 90.0]
    gate_sigmas: float  # 3.0
    acceleration_std: float  # 3.0
    min_gate: float  # 0.5
    min_static_points: int  # 10
    keyframe_distance: float  # 0.5
    keyframe_angle: float  # 2.0
    background_map_update: bool  # True
    min_matched_points: int  # 10
    initial_pose: ArrayLike  # identity
    ego_min_range: float  # 0.25
    ego_max_range: float  # 100.0
    ego_outlier_probability: float  # 0.4
    ego_success_probability: float  # 0.9999
    ego_inlier_threshold: float  # 0.15
    ego_zero_velocity_threshold: float  # 0.05
    ego_zero_velocity_sigma: float  # 0.025
    seed: int  # 1
    ego_consensus_voxel: float  # 1.0
    azimuth_std: float  # 0.0
    elevation_std: float  # 0.0
    active_radius: float  # 100.0
    keep_evicted: bool  # True
    region: float  # 4.0
    region_capacity: int  # 256
    region_min_points: int  # 8
    map_estimator: str  # 'refit'
    republish_kl: float  # 2.0
    refit_growth: float  # 0.5
    builder: str  # 'kmeans'
    downsample: float  # 0.25
    points_per_gaussian: float  # 4.0
    kmeans_iterations: int  # 8
    em_iterations: int  # 10
    min_std: float  # 0.05
    map_seed: int  # 1
    ndt_voxel: float  # 1.0
    ndt_min_points: int  # 5
    fit_index_cell: float  # 1.0
    association_gate: float  # 3.0
    degree: int  # 3
    rcs_adaptive: bool  # True
    incidence: str  # 'offset'
    rcs_rank_threshold: float  # 0.01
    rcs_min_explained: float  # 0.0
    coarse_levels: str  # 'merged'
    coarse_sigmas: list[float]  # [0.25]
    index_cell: float  # 1.0
    coarse_gate: float  # 3.0
    estimate_elevation_bias: bool  # False
    elevation_bias_window: int  # 100
    elevation_bias_min_speed: float  # 5.0
    rig_max_frame_span: float  # 0.1
    rig_velocity: bool  # True
    rig_rotation_rate: str  # 'yaw'
    rig_motion_compensation: bool  # True
    rig_calibrate: bool  # False
    rig_calibration_window: float  # 2.5
    rig_calibration_doppler_std: float  # 0.05
    rig_calibration_map_weight: float  # 1.0
    rig_calibration_prior: Sequence[float]  # [2.0, 0.1, 0.02]
    rig_calibration_observed: Sequence[float]  # [0.2, 0.03, 0.002]

class PlaceSearchOptions(TypedDict, total=False):
    """what RadarSlam and Relocalizer share beyond RadarOdometry's"""
    submap_distance: float  # 10.0
    descriptor: str  # 'scan-context'
    candidates: int  # 20
    max_scan_context_distance: float  # 0.4
    max_radon_distance: float  # 0.15
    submap_voxel: float  # 0.25
    channel: str  # 'both'
    scan_context_rings: int  # 20
    scan_context_sectors: int  # 60
    scan_context_max_range: float  # 80.0
    scan_context_rcs_floor: float  # -30.0
    radon_angles: int  # 60
    radon_offsets: int  # 64
    radon_cell: float  # 1.0
    radon_max_range: float  # 80.0
    verify_bev_cell: float  # 1.0
    verify_bev_search: float  # 12.0
    verify_min_associated: float  # 0.5
    verify_max_cost: float  # 6.0
    verify_max_translation_std: float  # 0.2
    verify_max_rotation_std: float  # 1.0
    verify_drift: float  # 0.05
    verify_min_drift: float  # 5.0
    verify_drift_deg: float  # 0.05
    verify_min_drift_deg: float  # 10.0
    verify_translation_floor_std: float  # 0.1
    verify_rotation_floor_std: float  # 0.5
    verify_kept_targets: int  # 64
    verify_min_overlap: float  # 0.4
    verify_budget: int  # 3
    verify_start_margin: float  # 10.0
    verify_start_margin_deg: float  # 20.0
    verify_solver: str  # 'mh-gn'
    verify_loss: str  # 'trivial'
    verify_loss_scale: float  # 1.0
    verify_rcs_likelihood: str  # 'decibel'
    verify_rcs_confidence: bool  # False
    verify_rcs_expected_spread: float  # 0.0
    verify_jacobians: str  # 'analytic'
    verify_gate: float  # 3.0
    verify_max_iterations: int  # 30
    verify_coarse_iterations: int  # 15
    verify_coarse_voxel_per_sigma: float  # 2.0
    verify_coarse_points: int  # 0
    verify_geometric_first: bool  # True
    verify_reassociate: bool  # True
    verify_reassociation_translation: float  # 0.01
    verify_reassociation_rotation: float  # 0.002
    verify_translation_tolerance: float  # 0.001
    verify_rotation_tolerance: float  # 0.0001
    verify_coarse_translation_tolerance: float  # 0.01
    verify_coarse_rotation_tolerance: float  # 0.001
    verify_pose_covariance: bool  # False
    verify_gn_max_step_halvings: int  # 8
    verify_gn_loss_curvature: bool  # False
    verify_ceres_dogleg: bool  # False
    verify_ceres_max_inner_iterations: int  # 2
    verify_ceres_max_exact_inner_iterations: int  # 8
    verify_ceres_blocks: str  # 'square-root'
    verify_ceres_threads: int  # 1
    verify_ceres_function_tolerance: float  # 1e-06
    verify_ceres_gradient_tolerance: float  # 1e-10
    verify_ceres_parameter_tolerance: float  # 1e-08
    verify_mh_starts: int  # 13
    verify_mh_xy_offset: float  # 2.0
    verify_mh_yaw_offset: float  # 0.1
    verify_builder: str  # 'kmeans'
    verify_downsample: float  # 0.25
    verify_points_per_gaussian: float  # 4.0
    verify_kmeans_iterations: int  # 8
    verify_em_iterations: int  # 10
    verify_min_std: float  # 0.05
    verify_map_seed: int  # 1
    verify_ndt_voxel: float  # 1.0
    verify_ndt_min_points: int  # 5
    verify_fit_index_cell: float  # 1.0
    verify_association_gate: float  # 3.0

class SlamOptions(OdometryOptions, PlaceSearchOptions, total=False):
    """option_fields("slam")"""
    min_loop_path: float  # 150.0
    loop_spacing: float  # 0.0
    odometry_translation_std: float  # 0.05
    odometry_drift: float  # 0.02
    odometry_rotation_std: float  # 0.1
    odometry_drift_deg: float  # 0.02
    asynchronous_back_end: bool  # True
    place_merge_distance: float  # 0.0
    place_merge_angle: float  # 45.0
    hold_map_points: bool  # True
    place_map_revisits: bool  # False
    revisit_candidates: bool  # True
    local_solve_margin: float  # 100.0
    loop_rejection: str  # 'graduated'
    loop_loss: str  # 'geman-mcclure'
    loop_loss_scale: float  # 3.0
    switch_prior_std: float  # 0.1
    graduation_factor: float  # 1.4
    graph_initialization: str  # 'current'
    graph_jacobians: str  # 'analytic'
    graph_max_iterations: int  # 100
    graph_function_tolerance: float  # 1e-06
    graph_threads: int  # 1

class RelocalizationOptions(OdometryOptions, PlaceSearchOptions, total=False):
    """option_fields("relocalization")"""
    confirm_window: int  # 3
    confirm_translation: float  # 1.0
    confirm_rotation: float  # 2.0
    ambiguous_translation: float  # 5.0
    ambiguous_rotation: float  # 5.0
    max_unmatched_scans: int  # 10

class DataError(ValueError): ...

class GaussianMap:
    """A Gaussian-RCS map; every array is a copy (the Gaussians are stored one by one, not as columns)."""
    def __len__(self: GaussianMap) -> int:
        ...
    @property
    def covariances(self) -> Any: ...
    @property
    def incidence(self) -> Any: ...
    @property
    def means(self) -> Any: ...
    @property
    def point_counts(self) -> Any: ...
    @property
    def rcs_coefficients(self) -> Any: ...
    @property
    def rcs_degrees(self) -> Any: ...
    @property
    def rcs_explained(self) -> Any: ...
    @property
    def rcs_inliers(self) -> Any: ...
    @property
    def rcs_medians(self) -> Any: ...
    @property
    def rcs_scales(self) -> Any: ...
    @property
    def rcs_spreads(self) -> Any: ...
    def rcs_weight(self: GaussianMap, likelihood: str = 'decibel', expected_spread: float = 0.0) -> float:
        """eq. 2's w_rcs chosen from the map's RCS fits (localize --w-rcs-from-map; docs/design.md)"""

class MatchResult:
    """The outcome of one scan match."""
    @property
    def converged(self) -> Any: ...
    @property
    def cost(self) -> Any: ...
    @property
    def geometric_residuals(self) -> Any: ...
    @property
    def information(self) -> Any: ...
    @property
    def iterations(self) -> Any: ...
    @property
    def pose(self) -> Any: ...
    @property
    def pose_tum(self) -> Any: ...
    @property
    def rcs_residuals(self) -> Any: ...
    @property
    def reason(self) -> Any: ...
    @property
    def time_ms(self) -> Any: ...

class RadarInertialOdometry:
    """Radar-inertial odometry (docs/design/odometry.md, "Radar-inertial odometry"): the radar odometry with the IMU's motion model named by imu_fusion: 'window', a sliding window of IMU states, or 'gyro', the gyro's rates for the prediction only. Threads may share one: its calls take turns."""
    def __init__(self: RadarInertialOdometry, imu: Any, radar_from_imu: Any = None, **kwargs) -> None:
        ...
    def __len__(self: RadarInertialOdometry) -> int:
        ...
    def calibration(self: RadarInertialOdometry) -> dict:
        """The window's tilt (rad, roll and pitch of the matcher's world against gravity), clock offset (s), T_radar_imu, and the standard deviations of those estimated and of the newest biases"""
    def imu_dropped(self: RadarInertialOdometry) -> dict:
        """The IMU samples dropped before the window saw them: 'beyond_range' (imu_gyro_range, imu_accel_range) and isolated 'spikes'"""
    def register(self: RadarInertialOdometry, scan: Scan) -> dict:
        """Adds the next scan; returns RadarOdometry.register's dict with 'inertial': the window's newest state (pose, velocity, gyro_bias, accel_bias), or None before the window started and with imu_fusion='gyro'"""
    def trajectory(self: RadarInertialOdometry) -> tuple:
        """(stamps (N,), poses (N, 7)) of the radar so far, in the matcher's world"""

class RadarOdometry:
    """Radar odometry on a map it builds as it goes (docs/design/odometry.md, "Odometry"): register scans in time order. Threads may share one: its calls take turns."""
    def __init__(self: RadarOdometry, **options: Unpack[OdometryOptions]) -> None:
        ...
    def __len__(self: RadarOdometry) -> int:
        ...
    def map(self: RadarOdometry) -> GaussianMap:
        """The map built so far, the Gaussians that left the active radius included"""
    @property
    def matchers_made(self) -> Any: ...
    def options(self: RadarOdometry) -> dict:
        """Every option by keyword, as odometry_options gives them"""
    def register(self: RadarOdometry, scan: Scan) -> dict:
        """Adds the next scan (stamps must increase); returns what happened to it as a dict: pose (4x4), velocity, matched, keyframe, reason, the information matrices, ..."""
    def trajectory(self: RadarOdometry) -> tuple:
        """(stamps (N,), poses (N, 7)) so far"""

class RadarSlam:
    """Radar SLAM (docs/design/slam.md, "SLAM"): odometry, keyframes with submaps, place recognition, verified loops on a pose graph. Threads may share one: its calls take turns."""
    def __init__(self: RadarSlam, **options: Unpack[SlamOptions]) -> None:
        ...
    def finish(self: RadarSlam) -> None:
        """Closes the last keyframe (described and searched): call after the last scan."""
    @property
    def keyframes(self) -> Any: ...
    def loops(self: RadarSlam) -> list:
        """Every compared candidate as a dict: query, candidate, distance, yaw, verified, accepted, relative, reason"""
    def odometry_trajectory(self: RadarSlam) -> tuple:
        """(stamps (N,), poses (N, 7)) of the odometry alone"""
    def place_map(self: RadarSlam, scans: Optional[list[Scan]] = None) -> GaussianMap:
        """The map of the place, with the keyframes as places: from the registered scans (in order), or without them from the static points the SLAM holds (hold_map_points; a revisit within place_merge_distance holds none)"""
    @property
    def place_map_bytes(self) -> Any: ...
    def register(self: RadarSlam, scan: Scan) -> None:
        """Adds the next scan (stamps must increase)."""
    def trajectory(self: RadarSlam) -> tuple:
        """(stamps (N,), poses (N, 7)): every scan at its keyframe's optimised pose"""

class Relocalizer:
    """Relocalisation in a map of RadarSlam without an initial pose (docs/design/slam.md, "Relocalisation"). Threads may share one: its calls take turns."""
    def __init__(self: Relocalizer, map: GaussianMap, **options: Unpack[RelocalizationOptions]) -> None:
        ...
    @property
    def first_fix(self) -> Any: ...
    def register(self: Relocalizer, scan: Scan) -> dict:
        """Adds the next scan; a dict with fixed, pose (4x4, or None before a fix), matched, reason"""

class Scan:
    """One radar scan: points (N, 3) in the radar frame, Doppler (m/s, positive receding) and RCS (dBsm), each a copy as a numpy array."""
    def __init__(self: Scan, points: Any, doppler: Any = None, rcs: Any = None, stamp: float = 0.0) -> None:
        ...
    def __len__(self: Scan) -> int:
        ...
    def __repr__(self: Scan) -> str:
        ...
    @property
    def doppler(self) -> Any: ...
    @property
    def has_doppler(self) -> Any: ...
    @property
    def has_rcs(self) -> Any: ...
    @property
    def points(self) -> Any: ...
    @property
    def rcs(self) -> Any: ...
    @property
    def stamp(self) -> Any: ...

class Sequence:
    """Scans in time order and, with ground truth, the pose of each."""
    def __len__(self: Sequence) -> int:
        ...
    @property
    def layout(self) -> Any: ...
    @property
    def poses(self) -> Any: ...
    @property
    def poses_matrix(self) -> Any: ...
    @property
    def scans(self) -> Any: ...
    @property
    def sources(self) -> Any: ...
    @property
    def stamps(self) -> Any: ...

def build_map(scans: Any, poses: Any = None, builder: str = 'kmeans', points_per_gaussian: float = 4.0, min_std: float = 0.05, incidence: str = 'offset', max_degree: int = 3, doppler_filter: bool = True) -> GaussianMap:
    """The map of `radargauss build-map`: from a Sequence with poses, or from a list of Scans and their poses T_world_radar (4x4 or [x y z qx qy qz qw]). builder: kmeans or voxel; incidence: offset, view or none."""

def calibrate_rig(path: str, imu: Any = None, body_from_imu: Any = None, **kwargs) -> dict:
    """Each radar's extrinsic and clock offset of a rig file against its first radar, over its drive (docs/design/rig.md, "Calibration of a rig"). A dict: rig (the radars as read_rig gives them, calibrated) and radars (per radar: name, body_from_radar, clock_offset, rotation_std (rad), translation_std (m), clock_offset_std (s), inf where unobserved; scans, doppler_points, map_points); gyro: whether the reference's rates came from the IMU. imu: (N, 7) [stamp wx wy wz ax ay az] on the body's clock, body_from_imu: T_body_imu (default identity): the reference's odometry with the IMU's window and its rates from the gyro."""

def compose(a: Any, b: Any) -> numpy.ndarray:
    """The rigid transform a * b as [x y z qx qy qz qw]."""

def estimate_rig_twist(scans: list[Scan], body_from_radar: Any, **kwargs) -> dict:
    """The body's velocity and angular velocity (body frame) from the Doppler of several radars' scans taken together, each radar at its body_from_radar (4x4 or [x y z qx qy qz qw]). A dict: success, reason, velocity, angular_velocity, covariance (6x6 of [v; w]), observed (the projector onto the observed directions), rank, inlier (per radar, per point)."""

def evaluate(estimate: tuple, reference: tuple, align: str = 'se3') -> dict:
    """ATE and RPE of `radargauss evaluate`: align se3, sim3, first or none."""

def initial_errors(scans: int, max_translation: float = 2.0, max_rotation_deg: float = 5.0, seed: int = 42) -> numpy.ndarray:
    """The seeded errors E of `radargauss localize` (its --max-translation, --max-rotation, --seed): the initial pose of scan i is compose(reference_i, E_i). (N, 7)."""

def match(scan: Scan, map: GaussianMap, initial: Any, **options: Unpack[MatchOptions]) -> MatchResult:
    """Matches a Scan against a GaussianMap, minimising eq. 2 coarse to fine as `radargauss localize` does."""

def match_options(**options: Unpack[MatchOptions]) -> dict:
    """Every option of match, the given keywords set (checked as match checks them), as a dict."""

def odometry_options(**options: Unpack[OdometryOptions]) -> dict:
    """Every option of RadarOdometry, the given keywords set (checked), as a dict."""

def option_fields(kind: str) -> list:
    """The keywords of match, RadarOdometry, RadarSlam, Relocalizer or the radar-inertial window ('match', 'odometry', 'slam', 'relocalization', 'radar_inertial'), and the rows of the matching map's and the joint refinement's tables that localize and refine read ('matching_map', 'joint_refinement'): one dict per option with its keyword, the C++ member it sets (path), type, doc, default, group, unit and range."""

def pose_matrices(poses: Any) -> numpy.ndarray:
    """Poses (N, 7) [x y z qx qy qz qw] (or (N, 4, 4)) as (N, 4, 4) matrices."""

def pose_matrix(pose: Any) -> numpy.ndarray:
    """A pose [x y z qx qy qz qw] (or 4x4) as its 4x4 matrix."""

def read_bag_poses(path: str, topic: str, child_frame: str = '') -> tuple:
    """Poses of a ROS 2 bag's topic (PoseStamped, Odometry, TFMessage with child_frame, or the last Path) as (stamps (N,), poses (N, 7))."""

def read_bag_topics(path: str) -> list:
    """The topics of a bag of any kind (ROS1 .bag, ROS 2 .db3 or .mcap, rosbag2 folder): dicts of name, type, messages and the first and last record time (s)."""

def read_imu(path: str) -> numpy.ndarray:
    """An IMU file (lines 'stamp wx wy wz ax ay az') as an (N, 7) array; DataError names the line"""

def read_map(path: str) -> GaussianMap:
    """Reads a .rgm map file (validated: docs/design/formats.md, "Bounds on input")."""

def read_pcd(path: str) -> Scan:
    """One PCD scan (ascii, binary or binary_compressed); the stamp from a <secs>.<nsecs>.pcd name."""

def read_rig(path: str) -> list:
    """The radars of a rig file, each a dict: name, sequence (a folder) or bag and topic, body_from_radar (4x4 T_body_radar), clock_offset (s: the radar's stamps minus the body's clock)."""

def read_sequence(path: str = '', gt: str = '', extrinsic: str = 'auto', bag: str = '', topic: str = '', rcs_field: str = '', doppler_field: str = '', elevation_bias_deg: float = 0.0) -> Sequence:
    """Reads a sequence as `radargauss info` does: a Snail-Radar folder, a folder of .pcd or .bin scans (path), or a bag (bag, topic: a ROS1 .bag, a ROS 2 .db3 or .mcap, a rosbag2 folder); gt: a TUM file of reference poses, extrinsic T_gt_radar; elevation_bias_deg removed from every point."""

def read_tum(path: str) -> tuple:
    """A TUM file as (stamps (N,), poses (N, 7) [x y z qx qy qz qw])."""

def relocalization_options(**options: Unpack[RelocalizationOptions]) -> dict:
    """Every option of Relocalizer, the given keywords set (checked), as a dict."""

def rig_odometry(path: str, imu: Any = None, body_from_imu: Any = None, **kwargs) -> dict:
    """The body's odometry from a rig file's radars (docs/design/rig.md, "Odometry on a rig"), with an IMU on the body when given ("An IMU on a rig"). A dict: trajectory ((stamps (N,), poses (N, 7)) of T_world_body), frame_radars (each frame's radars), velocity_measured, rig_velocity_measured (frames); with the IMU's window, inertial_state (the newest state, in the first radar's frame; None before the window started)."""

def set_threads(threads: int) -> None:
    """Worker threads of the parallel stages (0: all cores), as the tool's --threads."""

def simulate(seed: int = 1, scans: int = 0, config: str = '') -> Sequence:
    """The synthetic 4D radar drive of `radargauss simulate` (configs/synthetic_world.yaml) as a Sequence with its ground-truth poses; scans > 0 overrides the config's count."""

def slam_options(**options: Unpack[SlamOptions]) -> dict:
    """Every option of RadarSlam, the given keywords set (checked), as a dict."""

def write_map(path: str, map: GaussianMap) -> None:
    """Writes a .rgm map file atomically."""

def write_run_mcap(path: str, stamps: Any, poses: Any, map: Any = None, reference_stamps: Any = None, reference: Any = None, scans: Any = None, ellipsoid_sigma: float = 2.0) -> None:
    """Writes a trajectory (stamps (N,), poses (N, 7) or (N, 4, 4): T_map_radar), and optionally a GaussianMap, a reference and the scans (one per pose, registered by it) as an MCAP file a robotics viewer opens, as `radargauss export` does."""

def write_tum(path: str, stamps: Any, poses: Any) -> None:
    """Writes stamps (N,) and poses (N, 7) or (N, 4, 4) as a TUM file (9 decimals), atomically."""
