"""posefuse.Trajectory, reading / writing / detecting files, association:
against the C++ library's behaviour and messages."""
import os
import subprocess
import sys

import numpy as np
import pytest

import posefuse
from conftest import kitti_like


def traj_from(poses, stamps=None):
    stamps = np.arange(len(poses), dtype=float) if stamps is None else stamps
    return posefuse.Trajectory(stamps, poses)


@pytest.fixture
def drive():
    t, gt, est = kitti_like(200)
    return t, gt, est


def test_import_does_not_import_numpy_and_array_functions_say_they_need_it():
    code = ("import sys; sys.modules['numpy'] = None\n"
            "import posefuse\n"
            "assert 'numpy' not in sys.modules or sys.modules['numpy'] is None\n"
            "try:\n"
            "    posefuse.Trajectory([0.0], positions=[[0.0, 0.0, 0.0]])\n"
            "except ImportError as e:\n"
            "    print('ImportError:', e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    assert out.returncode == 0, out.stderr
    assert "ImportError: stamps needs numpy" in out.stdout
    assert "python3-numpy" in out.stdout


def test_arrays_are_read_only_views_that_keep_the_trajectory_alive(drive):
    t, gt, _ = drive
    traj = posefuse.Trajectory(t, gt)
    assert len(traj) == 200
    poses, positions, stamps = traj.poses, traj.positions, traj.stamps
    assert poses.shape == (200, 4, 4) and positions.shape == (200, 3) and stamps.shape == (200,)
    assert np.array_equal(poses, gt) and np.array_equal(positions, gt[:, :3, 3]) and np.array_equal(stamps, t)
    # No copy: the positions are the poses' last column, in the same memory.
    assert np.shares_memory(poses, positions)
    assert np.shares_memory(traj.stamps, stamps)
    for a in (poses, positions, stamps):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[0] = 1.0
    del traj
    assert np.array_equal(poses, gt)  # the views keep the C++ trajectory alive
    # evo's names.
    traj = posefuse.Trajectory(t, gt)
    assert np.array_equal(traj.positions_xyz, traj.positions)
    assert np.array_equal(traj.timestamps, traj.stamps)
    assert np.array_equal(traj.poses_se3, traj.poses)
    assert np.array_equal(traj.orientations_quat_wxyz, traj.quaternions)


def test_quaternions_are_w_x_y_z():
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    q = np.array([[1.0, 0, 0, 0], [c, 0, 0, s]])
    traj = posefuse.Trajectory([0.0, 1.0], positions=np.zeros((2, 3)), quaternions=q)
    assert np.allclose(traj.poses[1, :3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    assert np.allclose(traj.quaternions, q, atol=1e-15)
    # Without quaternions the rotations are the identity.
    traj = posefuse.Trajectory([0.0, 1.0], positions=[[1, 2, 3], [4, 5, 6]])
    assert np.array_equal(traj.poses[:, :3, :3], np.tile(np.eye(3), (2, 1, 1)))
    assert traj.positions.dtype == np.float64


def test_any_convertible_input_is_accepted(drive):
    t, gt, _ = drive
    reference = posefuse.Trajectory(t, gt).poses
    fortran = np.asfortranarray(gt)
    strided = np.concatenate([gt, gt], axis=0)[::2]  # non-contiguous
    for poses in (fortran, gt.tolist()):
        assert np.array_equal(posefuse.Trajectory(t, poses).poses, reference)
    assert np.array_equal(posefuse.Trajectory(t[::1], strided[:200]).poses[:100], strided[:100])
    # Integer stamps and positions.
    traj = posefuse.Trajectory(np.arange(3), positions=np.arange(9).reshape(3, 3))
    assert traj.stamps.tolist() == [0.0, 1.0, 2.0]


@pytest.mark.parametrize("stamps, kwargs, error, text", [
    (None, {"positions": np.zeros((2, 3))}, TypeError, "stamps must be an array of numbers, not None"),
    ([0.0, 1.0], {"positions": "abc"}, TypeError, "positions must be an array of numbers"),
    ([0.0, 1.0], {"positions": [["a", "b", "c"]] * 2}, TypeError, "positions must be an array of numbers"),
    ([0.0, 1.0], {"positions": np.zeros((2, 2))}, ValueError, "positions must have shape (N, 3) with N = len(stamps), got (2, 2)"),
    ([0.0, 1.0], {"positions": np.zeros((3, 3))}, ValueError, "got (3, 3)"),
    ([0.0, 1.0], {"poses": np.zeros((2, 3, 4))}, ValueError, "poses must have shape (N, 4, 4)"),
    ([[0.0, 1.0]], {"positions": np.zeros((2, 3))}, ValueError, "stamps must have shape (N,), got (1, 2)"),
    ([], {"positions": np.zeros((0, 3))}, ValueError, "a trajectory needs at least one pose"),
    ([0.0, 1.0], {}, ValueError, "give poses (N, 4, 4) or positions (N, 3)"),
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": [[2.0, 0, 0, 0]] * 2}, ValueError,
     "quaternions[0] has norm 2"),
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": np.zeros((2, 3))}, ValueError,
     "quaternions must have shape (N, 4)"),
    # A quaternion that is no rotation is refused, never taken as the identity.
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": [[1.0, 0, 0, 0], [np.nan, 0, 0, 1]]}, ValueError,
     "quaternions[1] = (nan, 0, 0, 1) (w, x, y, z) is not finite"),
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": [[1.0, 0, 0, 0], [1, np.inf, 0, 0]]}, ValueError,
     "quaternions[1] = (1, inf, 0, 0) (w, x, y, z) is not finite"),
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": [[1.0, 0, 0, -np.inf], [1, 0, 0, 0]]}, ValueError,
     "quaternions[0] = (1, 0, 0, -inf) (w, x, y, z) is not finite"),
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": [[1.0, 0, 0, 0], [0, 0, 0, 0]]}, ValueError,
     "quaternions[1] is zero: a zero quaternion is no rotation"),
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": [[1.0, 0, 0, 0], [1e-300, 0, 0, 0]]}, ValueError,
     "quaternions[1] has norm 1e-300, not 1 (within 1e-3)"),
    ([0.0, 1.0], {"positions": np.zeros((2, 3)), "quaternions": [[1.0, 0, 0, 0], [1e300, 1e300, 0, 0]]}, ValueError,
     "quaternions[1] has norm 1.414213562373095"),
    # The C++ library's messages (Trajectory::validate).
    ([0.0, np.nan], {"positions": np.zeros((2, 3))}, ValueError, "trajectory stamp 1 is not finite"),
    ([0.0, np.inf], {"positions": np.zeros((2, 3))}, ValueError, "trajectory stamp 1 is not finite"),
    ([0.0, 1.0], {"positions": [[0, 0, 0], [0, np.nan, 0]]}, ValueError, "trajectory pose 1 is not finite"),
    ([0.0, 1.0, 1.0], {"positions": np.zeros((3, 3))}, ValueError,
     "trajectory stamps are not strictly increasing at index 2"),
    ([0.0, 2.0, 1.0], {"positions": np.zeros((3, 3))}, ValueError,
     "trajectory stamps are not strictly increasing at index 2"),
])
def test_bad_arrays_raise_with_the_messages(stamps, kwargs, error, text):
    with pytest.raises(error) as e:
        posefuse.Trajectory(stamps, **kwargs)
    assert text in str(e.value)


def test_bad_poses_raise():
    poses = np.tile(np.eye(4), (2, 1, 1))
    poses[1, 0, 0] = 1.1
    with pytest.raises(ValueError, match=r"poses\[1\]: rotation is not orthonormal"):
        posefuse.Trajectory([0, 1], poses)
    poses[1, 0, 0] = -1.0
    with pytest.raises(ValueError, match=r"poses\[1\]: rotation is a reflection"):
        posefuse.Trajectory([0, 1], poses)
    poses[1, 0, 0] = 1.0
    poses[1, 3, 0] = 0.5
    with pytest.raises(ValueError, match=r"poses\[1\]: the last row must be \[0, 0, 0, 1\]"):
        posefuse.Trajectory([0, 1], poses)
    with pytest.raises(ValueError, match="either poses or positions"):
        posefuse.Trajectory([0, 1], np.tile(np.eye(4), (2, 1, 1)), positions=np.zeros((2, 3)))
    with pytest.raises(TypeError):
        posefuse.Trajectory()
    with pytest.raises(TypeError):
        posefuse.ape(None, None)


def test_tum_kitti_round_trip_and_detection(tmp_path, drive):
    t, gt, _ = drive
    traj = posefuse.Trajectory(t, gt)
    posefuse.write_trajectory(tmp_path / "a.tum", traj)
    posefuse.write_trajectory(str(tmp_path / "a.txt"), traj, format="kitti", times=tmp_path / "times.txt")
    assert posefuse.detect_format(tmp_path / "a.tum") == "tum"
    assert posefuse.detect_format(tmp_path / "a.txt") == "kitti"
    tum = posefuse.read_trajectory(tmp_path / "a.tum")
    assert tum.format == "tum" and tum.format_detected and tum.source == str(tmp_path / "a.tum")
    assert np.array_equal(tum.stamps, t)
    assert np.allclose(tum.poses, gt, atol=1e-15, rtol=0)
    kitti = posefuse.read_trajectory(tmp_path / "a.txt")
    assert kitti.frame_indexed and kitti.stamps.tolist() == list(range(200))
    assert np.array_equal(kitti.poses, traj.poses)  # shortest round-trip text, rotations exact
    timed = posefuse.read_trajectory(tmp_path / "a.txt", format="kitti", times=tmp_path / "times.txt")
    assert not timed.frame_indexed and np.array_equal(timed.stamps, t)
    with pytest.raises(posefuse.InvalidArgument, match="EuRoC files are read, not written"):
        posefuse.write_trajectory(tmp_path / "b.csv", traj, format="euroc")
    with pytest.raises(ValueError, match="unknown trajectory format 'kiti'"):
        posefuse.read_trajectory(tmp_path / "a.txt", format="kiti")
    with pytest.raises(ValueError, match="times only applies to KITTI files"):
        posefuse.read_trajectory(tmp_path / "a.tum", times=tmp_path / "times.txt")


def test_euroc_is_read_with_nanosecond_stamps(tmp_path):
    lines = ["#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []"]
    for k in range(5):
        lines.append("%d,%g,0,0,1,0,0,0" % (1403715273262142976 + k * 5000000, 0.1 * k))
    (tmp_path / "gt.csv").write_text("\n".join(lines) + "\n")
    traj = posefuse.read_trajectory(tmp_path / "gt.csv")
    assert traj.format == "euroc"
    assert traj.stamps[1] - traj.stamps[0] == pytest.approx(0.005, abs=1e-6)
    assert traj.positions[4, 0] == 0.4


def test_file_errors_carry_file_and_line(tmp_path, program):
    bad = tmp_path / "bad.tum"
    bad.write_text("0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n2 0 0 x 0 0 0 1\n")
    with pytest.raises(posefuse.FileError) as e:
        posefuse.read_trajectory(bad)
    text = str(e.value)
    assert text.startswith(str(bad) + ":3: ")
    assert isinstance(e.value, OSError) and isinstance(e.value, posefuse.Error)
    # The same text as the C++ program prints for the same file.
    proc = program.run(["--groundtruth", bad, "--estimate", bad], tmp_path, expect_ok=False)
    assert proc.returncode == 1 and text in proc.stderr
    with pytest.raises(posefuse.FileError, match="no poses"):
        (tmp_path / "empty.tum").write_text("# nothing\n")
        posefuse.read_trajectory(tmp_path / "empty.tum", format="tum")
    with pytest.raises(posefuse.FileError, match="cannot tell the format: 5 whitespace-separated fields"):
        (tmp_path / "five.txt").write_text("1 2 3 4 5\n")
        posefuse.read_trajectory(tmp_path / "five.txt")
    with pytest.raises(OSError):
        posefuse.read_trajectory(tmp_path / "missing.tum")


def test_repeated_stamps_follow_the_policy(tmp_path):
    f = tmp_path / "d.tum"
    f.write_text("0.1 1 0 0 0 0 0 1\n0.1 2 0 0 0 0 0 1\n0.2 3 0 0 0 0 0 1\n")
    with pytest.warns(UserWarning, match=r"d.tum:2: 1 pose\(s\) with a repeated timestamp dropped"):
        first = posefuse.read_trajectory(f)
    assert first.positions[:, 0].tolist() == [1, 3] and first.duplicates == "first"
    assert first.warnings == [str(f) + ":2: 1 pose(s) with a repeated timestamp dropped (kept the first of "
                              "each run; --duplicates error refuses them)"]
    with pytest.warns(UserWarning):
        last = posefuse.read_trajectory(f, duplicates="last")
    assert last.positions[:, 0].tolist() == [2, 3]
    with pytest.warns(UserWarning, match="repeated timestamp kept"):
        keep = posefuse.read_trajectory(f, duplicates="keep")
    assert keep.stamps.tolist() == [0.1, 0.1, 0.2]
    with pytest.raises(posefuse.RepeatedStampError) as e:
        posefuse.read_trajectory(f, duplicates="error")
    assert str(e.value) == str(f) + ":2: timestamp 0.1 repeats the previous one (0.1 on line 1)"
    assert isinstance(e.value, posefuse.FileError)
    with pytest.raises(ValueError, match="unknown duplicate-stamp policy 'all'"):
        posefuse.read_trajectory(f, duplicates="all")


def test_associate_matches_evo_rule():
    ref = posefuse.Trajectory(np.arange(10.0), positions=np.c_[np.arange(10.0), np.zeros(10), np.zeros(10)])
    est = posefuse.Trajectory([0.004, 2.0, 2.5, 7.011], positions=np.zeros((4, 3)))
    r, e = posefuse.associate(ref, est, max_time_diff=0.01)
    assert r.stamps.tolist() == [0.0, 2.0] and e.stamps.tolist() == [0.004, 2.0]
    r, e = posefuse.associate(ref, est, max_time_diff=0.5)
    assert r.stamps.tolist() == [0.0, 2.0, 2.0, 7.0]  # 2.5 ties 2 and 3: the first, as np.argmin
    r, e = posefuse.associate(ref, est, t_offset=-0.011, max_time_diff=0.001)
    assert e.stamps.tolist() == [7.011]
    with pytest.raises(ValueError, match="associate: found no matching timestamps"):
        posefuse.associate(ref, posefuse.Trajectory([100.0], positions=[[0, 0, 0]]))
