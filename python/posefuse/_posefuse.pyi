# Type stubs of the compiled module posefuse._posefuse (python/src/bind_*.cpp):
# trajectories and evaluation, Lie groups, pose graphs, IMU pre-integration and
# filters. The package posefuse re-exports all of it (__init__.pyi).
#
# Arrays are float64 numpy arrays; C-contiguous float64 inputs are read in
# place, anything else numpy can convert is converted once. Lie-group
# functions take one element or a stack with any leading shape (...); two-
# argument functions take equal leading shapes or one single element.
from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, "PathLike[str]"]
_Array = npt.ArrayLike
_Format = Literal["auto", "kitti", "tum", "euroc"]
_Duplicates = Literal["first", "last", "keep", "error"]
_Align = Literal["none", "se3", "sim3", "scale", "posyaw"]
_Relation = Literal["trans", "trans_part", "angle_deg", "angle_rad", "full", "rot_part", "point_distance",
                    "point_distance_error_ratio"]
_Plane = Literal["xy", "xz", "yz"]

class Error(Exception): ...
class FileError(Error, OSError): ...
class RepeatedStampError(FileError): ...
class InvalidArgument(Error, ValueError): ...
class DataError(Error, ValueError): ...

class Trajectory:
    def __init__(self, stamps: _Array, poses: Optional[_Array] = None, *, positions: Optional[_Array] = None,
                 quaternions: Optional[_Array] = None) -> None: ...
    def __len__(self) -> int: ...
    @property
    def stamps(self) -> npt.NDArray[np.float64]: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def poses(self) -> npt.NDArray[np.float64]: ...
    @property
    def quaternions(self) -> npt.NDArray[np.float64]: ...
    @property
    def source(self) -> Optional[str]: ...
    @property
    def format(self) -> Optional[str]: ...
    @property
    def format_detected(self) -> bool: ...
    @property
    def frame_indexed(self) -> bool: ...
    @property
    def duplicates(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def covariance_dim(self) -> int: ...
    @property
    def timestamps(self) -> npt.NDArray[np.float64]: ...
    @property
    def positions_xyz(self) -> npt.NDArray[np.float64]: ...
    @property
    def orientations_quat_wxyz(self) -> npt.NDArray[np.float64]: ...
    @property
    def poses_se3(self) -> npt.NDArray[np.float64]: ...

class Alignment:
    @property
    def rotation(self) -> npt.NDArray[np.float64]: ...
    @property
    def translation(self) -> npt.NDArray[np.float64]: ...
    @property
    def scale(self) -> float: ...
    @property
    def matrix(self) -> npt.NDArray[np.float64]: ...
    def apply(self, trajectory: Trajectory) -> Trajectory: ...

class Result:
    rmse: float
    mean: float
    median: float
    std: float
    min: float
    max: float
    sse: float
    count: int
    scale: float
    metric: str
    pose_relation: str
    unit: str
    warnings: list[str]
    @property
    def statistics(self) -> dict[str, float]: ...
    @property
    def errors(self) -> npt.NDArray[np.float64]: ...
    @property
    def stamps(self) -> npt.NDArray[np.float64]: ...
    @property
    def pairs(self) -> Optional[npt.NDArray[np.int64]]: ...
    @property
    def alignment(self) -> Alignment: ...
    @property
    def ref(self) -> Trajectory: ...
    @property
    def est(self) -> Trajectory: ...
    @property
    def est_aligned(self) -> Trajectory: ...
    @property
    def nees(self) -> Optional[dict[str, Any]]: ...
    def to_json(self) -> str: ...
    def __len__(self) -> int: ...

def detect_format(path: _Path) -> str: ...
def read_trajectory(path: _Path, format: _Format = "auto", times: Optional[_Path] = None,
                    duplicates: _Duplicates = "first") -> Trajectory: ...
def write_trajectory(path: _Path, trajectory: Trajectory, format: Literal["tum", "kitti"] = "tum",
                     times: Optional[_Path] = None) -> None: ...
def associate(ref: Trajectory, est: Trajectory, max_time_diff: float = 0.01,
              t_offset: float = 0.0) -> Tuple[Trajectory, Trajectory]: ...
def ape(ref: Trajectory, est: Trajectory, *, align: _Align = "none", pose_relation: _Relation = "trans",
        n_to_align: Optional[int] = None, align_origin: bool = False, project_to_plane: Optional[_Plane] = None,
        max_time_diff: float = 0.01, t_offset: float = 0.0, t_start: Optional[float] = None,
        t_end: Optional[float] = None, downsample: Optional[int] = None,
        motion_filter: Optional[Tuple[float, float]] = None) -> Result: ...
def rpe(ref: Trajectory, est: Trajectory, *, delta: float = 1.0,
        delta_unit: Literal["frames", "f", "m", "meters", "deg", "d", "rad", "r"] = "frames",
        all_pairs: bool = False, delta_tol: float = 0.1, pairs_from_reference: bool = False,
        align: _Align = "none", pose_relation: _Relation = "trans", n_to_align: Optional[int] = None,
        align_origin: bool = False, project_to_plane: Optional[_Plane] = None, max_time_diff: float = 0.01,
        t_offset: float = 0.0, t_start: Optional[float] = None, t_end: Optional[float] = None,
        downsample: Optional[int] = None, motion_filter: Optional[Tuple[float, float]] = None) -> Result: ...
def align(ref: Trajectory, est: Trajectory, method: _Align = "se3",
          n_to_align: Optional[int] = None) -> Tuple[Alignment, Trajectory]: ...

_F64 = npt.NDArray[np.float64]
_Loss = Literal["none", "huber", "cauchy"]
_Method = Literal["lm", "gn"]

# ---- Lie groups ------------------------------------------------------------------
# Elements are matrices: SO2 (..., 2, 2), SE2 (..., 3, 3), SO3 (..., 3, 3), SE3 (..., 4, 4),
# validated as the C++ constructors from matrices do (rotation within 1e-5, bottom row,
# finite; ValueError with the C++ text). Tangents, translation part first: SO2 (...) angle,
# SE2 (..., 3) [rho_x, rho_y, theta], SO3 (..., 3) rotation vector, SE3 (..., 6) [rho, phi];
# not validated (NaN in, NaN out). Right perturbations x (+) t = x Exp(t); every Jacobian is
# the right Jacobian (lie/lie.hpp), shape (..., d, d) with d the tangent dimension (SO2: 1).

class _LieGroup:
    @staticmethod
    def exp(tau: _Array, jacobian: bool = False) -> Union[_F64, Tuple[_F64, _F64]]:
        """Exp(tau); with jacobian=True (g, Jr(tau))."""
    @staticmethod
    def log(g: _Array, jacobian: bool = False) -> Union[_F64, Tuple[_F64, _F64]]:
        """Log(g), rotation angle in [0, pi] (SO2/SE2: theta in [-pi, pi)); with jacobian=True (tau, Jr^-1(tau))."""
    @staticmethod
    def inverse(g: _Array, jacobian: bool = False) -> Union[_F64, Tuple[_F64, _F64]]:
        """g^-1; with jacobian=True (g^-1, -Ad_g)."""
    @staticmethod
    def compose(a: _Array, b: _Array, jacobians: bool = False) -> Union[_F64, Tuple[_F64, _F64, _F64]]:
        """a b; with jacobians=True (c, J_c_a, J_c_b)."""
    @staticmethod
    def between(a: _Array, b: _Array, jacobians: bool = False) -> Union[_F64, Tuple[_F64, _F64, _F64]]:
        """a^-1 b (b expressed in a); with jacobians=True (d, J_d_a, J_d_b)."""
    @staticmethod
    def act(g: _Array, p: _Array, jacobians: bool = False) -> Union[_F64, Tuple[_F64, _F64, _F64]]:
        """g p for points (..., 2) (SO2, SE2) or (..., 3) (SO3, SE3); with jacobians=True (q, J_q_g, J_q_p)."""
    @staticmethod
    def plus(x: _Array, tau: _Array, jacobians: bool = False) -> Union[_F64, Tuple[_F64, _F64, _F64]]:
        """x Exp(tau); with jacobians=True (y, J_y_x, J_y_tau)."""
    @staticmethod
    def minus(y: _Array, x: _Array, jacobians: bool = False) -> Union[_F64, Tuple[_F64, _F64, _F64]]:
        """Log(x^-1 y); with jacobians=True (d, J_d_y, J_d_x)."""
    @staticmethod
    def adjoint(g: _Array) -> _F64:
        """Ad_g: g Exp(tau) = Exp(Ad_g tau) g."""
    @staticmethod
    def right_jacobian(tau: _Array) -> _F64:
        """Jr(tau)."""
    @staticmethod
    def right_jacobian_inverse(tau: _Array) -> _F64:
        """Jr(tau)^-1."""
    @staticmethod
    def left_jacobian(tau: _Array) -> _F64:
        """Jl(tau) = Jr(-tau)."""
    @staticmethod
    def left_jacobian_inverse(tau: _Array) -> _F64:
        """Jl(tau)^-1."""
    @staticmethod
    def hat(tau: _Array) -> _F64:
        """The Lie-algebra matrix of tau."""
    @staticmethod
    def vee(W: _Array) -> _F64:
        """Inverse of hat."""
    @staticmethod
    def normalize(g: _Array) -> _F64:
        """The nearest valid element (checked within 1e-5, then projected)."""
    @staticmethod
    def identity() -> _F64:
        """The identity matrix of the group."""

class SO2(_LieGroup):
    """SO(2): planar rotations (..., 2, 2); tangent theta (...) rad."""
    @staticmethod
    def from_angle(theta: _Array) -> _F64:
        """Rotation matrices (..., 2, 2) of angles (...) (SO2.exp)."""
    @staticmethod
    def angle(R: _Array) -> _F64:
        """Angles in [-pi, pi) of rotation matrices (SO2.log)."""

class SE2(_LieGroup):
    """SE(2): planar rigid motions (..., 3, 3); tangent [rho_x, rho_y, theta]."""
    @staticmethod
    def from_xytheta(pose: _Array) -> _F64:
        """Matrices (..., 3, 3) of poses (..., 3) [x, y, theta]."""
    @staticmethod
    def to_xytheta(T: _Array) -> _F64:
        """Poses (..., 3) [x, y, theta], theta in [-pi, pi)."""

class SO3(_LieGroup):
    """SO(3): rotations (..., 3, 3), body -> world; tangent = rotation vector (..., 3)."""
    @staticmethod
    def from_quaternion(q: _Array, order: Literal["wxyz", "xyzw"] = "wxyz") -> _F64:
        """Rotation matrices of quaternions (..., 4), normalised; zero or non-finite raises ValueError."""
    @staticmethod
    def to_quaternion(R: _Array, order: Literal["wxyz", "xyzw"] = "wxyz") -> _F64:
        """Unit quaternions (..., 4) with w >= 0."""

class SE3(_LieGroup):
    """SE(3): rigid motions (..., 4, 4) (T_w_b); tangent [rho (3), phi (3)]."""
    @staticmethod
    def from_rt(R: _Array, t: _Array) -> _F64:
        """Matrices (..., 4, 4) from rotations (..., 3, 3) and translations (..., 3)."""

# ---- pose graphs -----------------------------------------------------------------

class PoseGraphSummary:
    """What a pose-graph optimisation did."""
    @property
    def initial_cost(self) -> float:
        """g2o chi2 before (without robust losses)."""
    @property
    def final_cost(self) -> float:
        """g2o chi2 after."""
    @property
    def iterations(self) -> int:
        """Linear solves (accepted and rejected steps)."""
    @property
    def accepted(self) -> int:
        """Steps that decreased the cost."""
    @property
    def termination(self) -> Literal["function_tolerance", "gradient_tolerance", "parameter_tolerance",
                                     "max_iterations", "no_progress"]:
        """Why it stopped."""
    @property
    def solve_time_s(self) -> float:
        """Wall time of optimize() (s)."""
    @property
    def planar(self) -> bool:
        """Solved on (x, y, yaw) blocks."""

class PoseGraph4Dof:
    """4-DoF pose graph (x, y, z, yaw; roll and pitch held per node); a planar g2o graph is this with z = 0.
    Cost: g2o's chi2."""
    def __init__(self) -> None: ...
    def add_node(self, id: int, pose: _Array, fixed: bool = False, roll: float = 0.0, pitch: float = 0.0) -> None:
        """Adds node id at pose (4,) [x, y, z, yaw] or (3,) [x, y, yaw]."""
    def add_nodes(self, ids: _Array, poses: _Array, fixed: Optional[_Array] = None,
                  roll_pitch: Optional[_Array] = None) -> None:
        """Adds nodes ids (N,) at poses (N, 4) or (N, 3); fixed (N,) bool; roll_pitch (N, 2)."""
    def add_edge(self, i: int, j: int, dp: _Array, dyaw: float, information: _Array, loss: _Loss = "none",
                 loss_scale: float = 1.0) -> int:
        """Adds edge i -> j: dp (3,) or (2,) in i's frame, dyaw, information (4, 4) [x, y, z, yaw] or (3, 3)
        [x, y, theta]. Returns the edge index."""
    def add_edges(self, i: _Array, j: _Array, dp: _Array, dyaw: _Array, information: _Array, loss: _Loss = "none",
                  loss_scale: float = 1.0) -> None:
        """Adds M edges: dp (M, 3) or (M, 2), dyaw (M,), information (M, 4, 4), (M, 3, 3) or one matrix."""
    def set_fixed(self, id: int, fixed: bool = True) -> None: ...
    def is_fixed(self, id: int) -> bool: ...
    @property
    def num_nodes(self) -> int: ...
    @property
    def num_edges(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def ids(self) -> npt.NDArray[np.int64]: ...
    @property
    def fixed(self) -> npt.NDArray[np.bool_]: ...
    @property
    def poses(self) -> _F64:
        """(N, 4) [x, y, z, yaw]."""
    @property
    def roll_pitch(self) -> _F64:
        """(N, 2) [roll, pitch]."""
    def pose(self, id: int) -> _F64:
        """(4,) [x, y, z, yaw]."""
    def set_pose(self, id: int, pose: _Array) -> None:
        """Moves node id to (4,) or (3,); roll and pitch kept."""
    @property
    def edges(self) -> Dict[str, object]:
        """i, j (M,), dp (M, 3), dyaw (M,), information (M, 4, 4), loss [(name, scale)]."""
    def cost(self) -> float: ...
    def is_planar(self) -> bool: ...
    def validate(self) -> None: ...
    def initialize_rotation_first(self) -> None:
        """Chordal yaw, then a linear translation solve (Carlone et al. 2015)."""
    def optimize(self, method: _Method = "lm", max_iterations: int = 100, function_tolerance: float = 1e-10,
                 gradient_tolerance: float = 1e-12, parameter_tolerance: float = 1e-10, initial_lambda: float = 1e-5,
                 planar_fast_path: bool = True) -> PoseGraphSummary:
        """Levenberg-Marquardt or Gauss-Newton; the first node is held when none is fixed."""

class PoseGraphSE3:
    """SE(3) pose graph with g2o's EdgeSE3 error and 6x6 information [x, y, z, qx, qy, qz]."""
    def __init__(self) -> None: ...
    def add_node(self, id: int, T: _Array, fixed: bool = False) -> None: ...
    def add_nodes(self, ids: _Array, poses: _Array, fixed: Optional[_Array] = None) -> None:
        """ids (N,), poses (N, 4, 4)."""
    def add_edge(self, i: int, j: int, T_ij: _Array, information: _Array, loss: _Loss = "none",
                 loss_scale: float = 1.0) -> int: ...
    def add_edges(self, i: _Array, j: _Array, measurements: _Array, information: _Array, loss: _Loss = "none",
                  loss_scale: float = 1.0) -> None:
        """measurements (M, 4, 4), information (M, 6, 6) or (6, 6)."""
    def set_fixed(self, id: int, fixed: bool = True) -> None: ...
    def is_fixed(self, id: int) -> bool: ...
    @property
    def num_nodes(self) -> int: ...
    @property
    def num_edges(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def ids(self) -> npt.NDArray[np.int64]: ...
    @property
    def fixed(self) -> npt.NDArray[np.bool_]: ...
    @property
    def poses(self) -> _F64:
        """(N, 4, 4)."""
    def pose(self, id: int) -> _F64: ...
    def set_pose(self, id: int, T: _Array) -> None: ...
    @property
    def edges(self) -> Dict[str, object]:
        """i, j (M,), measurements (M, 4, 4), information (M, 6, 6), loss."""
    def cost(self) -> float: ...
    def validate(self) -> None: ...
    def initialize_chordal(self) -> None:
        """Chordal rotations projected to SO(3), then a linear translation solve."""
    def optimize(self, method: _Method = "lm", max_iterations: int = 100, function_tolerance: float = 1e-10,
                 gradient_tolerance: float = 1e-12, parameter_tolerance: float = 1e-10,
                 initial_lambda: float = 1e-5) -> PoseGraphSummary: ...

def read_g2o(path: _Path, loss: _Loss = "none", loss_scale: float = 1.0) -> Union[PoseGraph4Dof, PoseGraphSE3]:
    """A 2-D g2o file as a planar PoseGraph4Dof, a 3-D one as a PoseGraphSE3 (FileError 'file:line: reason')."""

def write_g2o(path: _Path, graph: Union[PoseGraph4Dof, PoseGraphSE3]) -> None:
    """A planar PoseGraph4Dof as a 2-D g2o file, a PoseGraphSE3 as a 3-D one."""

# ---- inertial ----------------------------------------------------------------------

class ImuNoise:
    """Continuous-time IMU noise figures (Kalibr / EuRoC imu.yaml)."""
    gyro_noise_density: float
    accel_noise_density: float
    gyro_random_walk: float
    accel_random_walk: float
    def __init__(self, gyro_noise_density: float = 1.6968e-4, accel_noise_density: float = 2.0e-3,
                 gyro_random_walk: float = 1.9393e-5, accel_random_walk: float = 3.0e-3) -> None: ...

class Preintegration:
    """IMU pre-integration between keyframes i and j (frame i); made by preintegrate()."""
    @property
    def delta_p(self) -> _F64: ...
    @property
    def delta_R(self) -> _F64: ...
    @property
    def delta_v(self) -> _F64: ...
    @property
    def dt(self) -> float: ...
    @property
    def covariance(self) -> _F64:
        """(15, 15) over [dp, dphi, dv, dba, dbg]."""
    @property
    def bias_jacobian(self) -> _F64:
        """(9, 6) d[dp, dphi, dv] / d[b_a, b_g]."""
    @property
    def bias_accel(self) -> _F64: ...
    @property
    def bias_gyro(self) -> _F64: ...
    @property
    def noise(self) -> ImuNoise: ...
    @property
    def sample_count(self) -> int: ...
    @property
    def start_t_ns(self) -> int: ...
    @property
    def end_t_ns(self) -> int: ...
    @overload
    def corrected(self, bias_accel: _Array, bias_gyro: _Array) -> Tuple[_F64, _F64, _F64]: ...
    @overload
    def corrected(self, bias_accel: _Array, bias_gyro: _Array, jacobian: bool) -> Tuple[_F64, ...]: ...
    def update_bias(self, bias_accel: _Array, bias_gyro: _Array) -> bool: ...
    def reintegrate(self, bias_accel: _Array, bias_gyro: _Array) -> None: ...

def preintegrate(t: _Array, accel: _Array, gyro: _Array, bias_accel: _Array = ..., bias_gyro: _Array = ...,
                 noise: ImuNoise = ..., t0: Optional[Union[int, float]] = None, t1: Optional[Union[int, float]] = None,
                 max_gap: float = 0.05) -> Preintegration:
    """Stamps t (N,) (int = ns, float = s), accel (N, 3) m/s^2, gyro (N, 3) rad/s; t0/t1 cut [t0, t1]."""

class ImuState:
    """Keyframe state [p, R, v, b_a, b_g]; tangent [dp, dphi, dv, dba, dbg]."""
    def __init__(self, p: Optional[_Array] = None, R: Optional[_Array] = None, v: Optional[_Array] = None,
                 bias_accel: Optional[_Array] = None, bias_gyro: Optional[_Array] = None) -> None: ...
    @property
    def p(self) -> _F64: ...
    @property
    def R(self) -> _F64: ...
    @property
    def v(self) -> _F64: ...
    @property
    def bias_accel(self) -> _F64: ...
    @property
    def bias_gyro(self) -> _F64: ...
    def plus(self, d: _Array) -> "ImuState": ...
    def minus(self, x: "ImuState") -> _F64: ...

class ImuFactor:
    """IMU factor of one pre-integrated interval (Forster et al. 2017 eq 45)."""
    def __init__(self, preintegration: Preintegration, gravity: _Array = ...) -> None: ...
    def residual(self, xi: ImuState, xj: ImuState, jacobians: bool = False,
                 whitened: bool = False) -> Union[_F64, Tuple[_F64, _F64, _F64]]:
        """r (15,) [r_p, r_phi, r_v, r_ba, r_bg]; with jacobians=True (r, J_r_i, J_r_j)."""
    def predict(self, xi: ImuState) -> ImuState: ...
    @property
    def covariance(self) -> _F64: ...
    @property
    def whitening(self) -> _F64: ...
    @property
    def dt(self) -> float: ...

def align_visual_inertial(T_c0_c: _Array, T_b_c: _Array, preintegrations: List[Preintegration],
                          gravity_norm: float = 9.81, min_accel_std: float = 0.25,
                          max_gravity_norm_error: float = 1.0, refinement_iterations: int = 4) -> Dict[str, object]:
    """VINS-Mono's visual-inertial alignment of 4 or more keyframes: status, ok, scale, gravity_c0, gyro_bias,
    velocity_c0, R_w_c0, T_w_b, velocity_w, accel_std, gravity_norm_unrefined, preintegrations (copies)."""

# ---- filters -------------------------------------------------------------------------

class EkfRun:
    """A recorded EKF run over N steps."""
    @property
    def model(self) -> Literal["seed000", "constant_velocity", "unicycle", "se2_odometry"]: ...
    @property
    def states(self) -> _F64: ...
    @property
    def covariances(self) -> _F64: ...
    @property
    def predicted_states(self) -> _F64: ...
    @property
    def predicted_covariances(self) -> _F64: ...
    @property
    def jacobians(self) -> _F64: ...
    @property
    def nis(self) -> _F64: ...
    @property
    def innovations(self) -> _F64: ...
    @property
    def status(self) -> List[str]: ...
    def __len__(self) -> int: ...

def ekf_seed000(x0: _Array, P0: _Array, displacements: _Array, fixes: _Array, R: _Array, Q: _Array,
                mask: Optional[_Array] = None, gate: float = ...) -> EkfRun:
    """Seed 000: position x' = x + u (process noise R), position fixes (noise Q)."""

def ekf_constant_velocity(x0: _Array, P0: _Array, dt: _Array, fixes: _Array, q: float, R: _Array,
                          mask: Optional[_Array] = None, gate: float = ...) -> EkfRun:
    """State [px, py, vx, vy]; white-noise acceleration q; position fixes (noise R)."""

def ekf_unicycle(x0: _Array, P0: _Array, controls: _Array, dt: _Array, fixes: _Array, control_cov: _Array,
                 R: _Array, integration: Literal["exact_arc", "euler"] = "exact_arc",
                 mask: Optional[_Array] = None, gate: float = ...) -> EkfRun:
    """State [x, y, theta]; controls (N, 2) [v, w]; pose fixes (N, 3)."""

def ekf_se2_odometry(x0: _Array, P0: _Array, increments: _Array, fixes: _Array, R: _Array,
                     xy_sigma_per_sqrt_m: float = 0.02, theta_sigma_per_sqrt_m: float = 0.005,
                     theta_sigma_per_sqrt_rad: float = 0.03, mask: Optional[_Array] = None,
                     gate: float = ...) -> EkfRun:
    """State [x, y, theta]; body-frame increments (N, 3) [dx, dy, dtheta]; pose fixes (N, 3)."""

def rts_smooth(run: EkfRun) -> Tuple[_F64, _F64]:
    """Rauch-Tung-Striebel smoothing: (states (N, D), covariances (N, D, D))."""
