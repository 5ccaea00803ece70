"""posefuse.ape / rpe / align against the C++ program evaluate_trajectory on
the same files and options: Result.to_json() must equal the program's
--save-results document character for character (so every number agrees to
the last bit), on synthetic drives and on the real KITTI 06 and EuRoC
V1_01 files (skipped, with the reason, when the data folder is absent)."""
import json

import numpy as np
import pytest

import posefuse
from conftest import kitti_like


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A 600-pose KITTI-like drive and its drifting estimate as KITTI files
    (frame by frame), with a times file, and as TUM files (the estimate's
    stamps shifted by 3 ms, every 2nd pose)."""
    d = tmp_path_factory.mktemp("drive")
    t, gt, est = kitti_like(600, seed=7)
    ref = posefuse.Trajectory(t, gt)
    posefuse.write_trajectory(d / "gt.txt", ref, format="kitti", times=d / "times.txt")
    posefuse.write_trajectory(d / "est.txt", posefuse.Trajectory(t, est), format="kitti")
    posefuse.write_trajectory(d / "gt.tum", ref)
    posefuse.write_trajectory(d / "est.tum", posefuse.Trajectory(t[::2] + 0.003, est[::2]))
    return d


# (Python keyword arguments, the program's flags): every option of the program.
APE_CASES = [
    ({}, []),
    ({"align": "se3"}, ["--align", "se3"]),
    ({"align": "sim3"}, ["--align", "sim3"]),
    ({"align": "scale"}, ["--align", "scale"]),
    ({"align": "posyaw"}, ["--align", "posyaw"]),
    ({"align_origin": True}, ["--align-origin"]),
    ({"align": "se3", "n_to_align": 50}, ["--align", "se3", "--n-to-align", "50"]),
    ({"align": "se3", "project_to_plane": "xz"}, ["--align", "se3", "--project-to-plane", "xz"]),
    ({"align": "se3", "pose_relation": "angle_deg"}, ["--align", "se3", "--pose-relation", "angle_deg"]),
    ({"pose_relation": "angle_rad"}, ["--pose-relation", "angle_rad"]),
    ({"align": "sim3", "pose_relation": "full"}, ["--align", "sim3", "--pose-relation", "full"]),
    ({"pose_relation": "rot_part"}, ["--pose-relation", "rot_part"]),
    ({"pose_relation": "point_distance"}, ["--pose-relation", "point_distance"]),
    ({"align": "se3", "downsample": 100}, ["--align", "se3", "--downsample", "100"]),
]
TIMED_CASES = [  # need stamps: TUM files
    ({"align": "se3"}, ["--align", "se3"]),
    ({"align": "se3", "t_offset": -0.003, "max_time_diff": 0.001},
     ["--align", "se3", "--t-offset", "-0.003", "--max-time-diff", "0.001"]),
    ({"align": "se3", "t_start": 10.0, "t_end": 40.0}, ["--align", "se3", "--t-start", "10", "--t-end", "40"]),
    ({"align": "se3", "motion_filter": (1.0, 1.0)}, ["--align", "se3", "--motion-filter", "1,1"]),
]
RPE_CASES = [
    ({}, []),
    ({"delta": 10}, ["--delta", "10"]),
    ({"delta": 10, "all_pairs": True}, ["--delta", "10", "--all-pairs"]),
    ({"delta": 100, "delta_unit": "m"}, ["--delta", "100", "--delta-unit", "m"]),
    ({"delta": 100, "delta_unit": "m", "all_pairs": True}, ["--delta", "100", "--delta-unit", "m", "--all-pairs"]),
    ({"delta": 100, "delta_unit": "m", "all_pairs": True, "delta_tol": 0.01},
     ["--delta", "100", "--delta-unit", "m", "--all-pairs", "--delta-tol", "0.01"]),
    ({"delta": 50, "delta_unit": "m", "pairs_from_reference": True},
     ["--delta", "50", "--delta-unit", "m", "--pairs-from-reference"]),
    ({"delta": 20, "delta_unit": "deg"}, ["--delta", "20", "--delta-unit", "deg"]),
    ({"delta": 0.3, "delta_unit": "rad", "all_pairs": True}, ["--delta", "0.3", "--delta-unit", "rad", "--all-pairs"]),
    ({"delta": 100, "delta_unit": "m", "pose_relation": "angle_deg"},
     ["--delta", "100", "--delta-unit", "m", "--pose-relation", "angle_deg"]),
    ({"delta": 100, "delta_unit": "m", "pose_relation": "point_distance_error_ratio"},
     ["--delta", "100", "--delta-unit", "m", "--pose-relation", "point_distance_error_ratio"]),
    ({"delta": 10, "align": "sim3"}, ["--delta", "10", "--align", "sim3"]),
    ({"delta": 10, "pose_relation": "full", "project_to_plane": "xz"},
     ["--delta", "10", "--pose-relation", "full", "--project-to-plane", "xz"]),
]


def both(program, tmp_path, gt, est, flags, metric_flags=()):
    """The program's JSON text for gt/est with flags."""
    return program.run(["--groundtruth", gt, "--estimate", est] + list(metric_flags) + flags, tmp_path)


@pytest.mark.parametrize("kwargs, flags", APE_CASES)
def test_ape_equals_the_program_frame_by_frame(files, program, tmp_path, kwargs, flags):
    gt, est = files / "gt.txt", files / "est.txt"
    r = posefuse.ape(posefuse.read_trajectory(str(gt)), posefuse.read_trajectory(str(est)), **kwargs)
    assert r.to_json() == both(program, tmp_path, gt, est, flags)


@pytest.mark.parametrize("kwargs, flags", TIMED_CASES)
def test_ape_equals_the_program_by_stamps(files, program, tmp_path, kwargs, flags):
    gt, est = files / "gt.tum", files / "est.tum"
    r = posefuse.ape(posefuse.read_trajectory(str(gt)), posefuse.read_trajectory(str(est)), **kwargs)
    assert r.to_json() == both(program, tmp_path, gt, est, flags)
    # A KITTI file stamped by its times file against a TUM file.
    gt_kitti = posefuse.read_trajectory(str(files / "gt.txt"), times=str(files / "times.txt"))
    r = posefuse.ape(gt_kitti, posefuse.read_trajectory(str(est)), **kwargs)
    assert r.to_json() == both(program, tmp_path, files / "gt.txt", est,
                               flags + ["--times", files / "times.txt"])


@pytest.mark.parametrize("kwargs, flags", RPE_CASES)
def test_rpe_equals_the_program(files, program, tmp_path, kwargs, flags):
    gt, est = files / "gt.txt", files / "est.txt"
    r = posefuse.rpe(posefuse.read_trajectory(str(gt)), posefuse.read_trajectory(str(est)), **kwargs)
    assert r.to_json() == both(program, tmp_path, gt, est, flags, ["--metric", "rpe"])
    assert len(r.errors) == len(r.pairs) == r.count


def test_the_issue_example_works_as_written(files, program, tmp_path):
    gt = posefuse.read_trajectory(str(files / "gt.txt"))
    est = posefuse.read_trajectory(str(files / "est.txt"))
    r = posefuse.ape(gt, est, align="se3")
    assert len(r.errors) == 600
    expected = program.json(["--groundtruth", files / "gt.txt", "--estimate", files / "est.txt", "--align", "se3"],
                            tmp_path)
    assert (r.rmse, r.mean, r.max) == (expected["rmse"], expected["mean"], expected["max"])
    r = posefuse.rpe(gt, est, delta=100, delta_unit="m", all_pairs=True)
    expected = program.json(["--groundtruth", files / "gt.txt", "--estimate", files / "est.txt", "--metric", "rpe",
                             "--delta", "100", "--delta-unit", "m", "--all-pairs"], tmp_path)
    assert r.rmse == expected["rmse"]


def test_result_contents(files):
    gt = posefuse.read_trajectory(str(files / "gt.tum"))
    est = posefuse.read_trajectory(str(files / "est.tum"))
    r = posefuse.ape(gt, est, align="sim3")
    doc = json.loads(r.to_json())
    e = r.errors
    assert r.count == len(e) == 300 and not e.flags.writeable
    # The statistics are numpy's definitions of the same errors.
    assert r.rmse == pytest.approx(np.sqrt(np.mean(e ** 2)), rel=1e-14)
    assert r.std == pytest.approx(np.std(e), rel=1e-12)
    assert r.median == np.median(e) and r.min == e.min() and r.max == e.max()
    assert r.statistics == {k: doc[k] for k in ("rmse", "mean", "median", "std", "min", "max", "sse")}
    assert np.array_equal(r.stamps, doc["stamps_s"])
    # The alignment maps the estimate's positions onto the reference.
    a = r.alignment
    assert a.scale == r.scale == doc["scale"]
    p = r.est.positions
    assert np.allclose(r.est_aligned.positions, a.scale * p @ a.rotation.T + a.translation, atol=1e-9, rtol=0)
    assert np.allclose(a.matrix[:3, :3], a.scale * a.rotation) and np.array_equal(a.matrix[3], [0, 0, 0, 1])
    assert np.allclose(np.linalg.norm(r.est_aligned.positions - r.ref.positions, axis=1), e, atol=1e-12, rtol=0)
    # align() on the associated poses gives the same similarity.
    a2, aligned = posefuse.align(r.ref, r.est, "sim3")
    assert np.array_equal(a2.rotation, a.rotation) and a2.scale == a.scale
    assert np.array_equal(aligned.poses, r.est_aligned.poses)
    assert r.pairs is None and r.nees is None and "APE trans, alignment sim3: 300 values" in repr(r)


def test_nees_of_an_estimate_with_covariance(tmp_path, program):
    t, gt, est = kitti_like(100, seed=3)
    posefuse.write_trajectory(tmp_path / "gt.tum", posefuse.Trajectory(t, gt))
    lines = []
    for k in range(100):
        p = est[k, :3, 3]
        q = posefuse.Trajectory([0.0], est[k:k + 1]).quaternions[0]
        lines.append("%r %r %r %r %r %r %r %r 0.04 0 0 0.04 0 0.04" % (t[k], p[0], p[1], p[2], q[1], q[2], q[3], q[0]))
    (tmp_path / "est.tum").write_text("\n".join(lines) + "\n")
    est_traj = posefuse.read_trajectory(str(tmp_path / "est.tum"))
    assert est_traj.covariance_dim == 3
    r = posefuse.ape(posefuse.read_trajectory(str(tmp_path / "gt.tum")), est_traj, align="se3")
    assert r.nees["dim"] == 3 and len(r.nees["values"]) == 100
    assert r.to_json() == both(program, tmp_path, tmp_path / "gt.tum", tmp_path / "est.tum", ["--align", "se3"])


def test_duplicates_keep_pairs_every_repeat_as_evo(tmp_path, program):
    # The shorter file (the estimate) repeats stamp 2: under keep both lines
    # pair with reference pose 2 (evo's association), under first one does.
    ref = posefuse.Trajectory(np.arange(10.0), positions=np.c_[np.arange(10.0), np.zeros((10, 2))])
    posefuse.write_trajectory(tmp_path / "ref.tum", ref)
    (tmp_path / "est.tum").write_text("0 0 0 0 0 0 0 1\n1 1 0.1 0 0 0 0 1\n2 2 0.2 0 0 0 0 1\n"
                                      "2 2 0.4 0 0 0 0 1\n3 3 0 0 0 0 0 1\n4 4 0 0 0 0 0 1\n")
    with pytest.warns(UserWarning):
        est = posefuse.read_trajectory(str(tmp_path / "est.tum"), duplicates="keep")
    gt = posefuse.read_trajectory(str(tmp_path / "ref.tum"), duplicates="keep")
    r = posefuse.ape(gt, est)
    assert r.count == 6 and r.rmse == pytest.approx(np.sqrt(0.21 / 6), rel=1e-14)
    assert r.to_json() == both(program, tmp_path, tmp_path / "ref.tum", tmp_path / "est.tum",
                               ["--duplicates", "keep"])
    with pytest.warns(UserWarning):
        first = posefuse.ape(gt, posefuse.read_trajectory(str(tmp_path / "est.tum")))
    assert first.count == 5 and first.rmse == pytest.approx(0.1, rel=1e-14)


def test_trajectories_from_arrays_are_evaluated_by_stamps(files):
    t, gt, est = kitti_like(600, seed=7)
    from_file = posefuse.ape(posefuse.read_trajectory(str(files / "gt.tum")),
                             posefuse.read_trajectory(str(files / "est.tum")), align="se3")
    from_arrays = posefuse.ape(posefuse.Trajectory(t, gt), posefuse.Trajectory(t[::2] + 0.003, est[::2]),
                               align="se3")
    assert from_arrays.rmse == pytest.approx(from_file.rmse, rel=1e-9)  # files hold shortest round-trip text
    assert json.loads(from_arrays.to_json())["options"]["groundtruth"] == "(arrays)"


@pytest.mark.parametrize("call, error, text", [
    (lambda g, e: posefuse.ape(g, e, align="affine"), ValueError,
     "unknown alignment 'affine' (expected none, se3, sim3, scale or posyaw)"),
    (lambda g, e: posefuse.ape(g, e, pose_relation="x"), ValueError, "unknown pose relation"),
    (lambda g, e: posefuse.ape(g, e, pose_relation="point_distance_error_ratio"), ValueError, "is an RPE measure"),
    (lambda g, e: posefuse.ape(g, e, align="se3", align_origin=True), ValueError, "exclude each other"),
    (lambda g, e: posefuse.ape(g, e, n_to_align=10), ValueError, "n_to_align needs align="),
    (lambda g, e: posefuse.ape(g, e, align="se3", n_to_align=2), ValueError, "n_to_align must be >= 3"),
    (lambda g, e: posefuse.ape(g, e, t_offset=1.0), ValueError, "need timestamps"),
    (lambda g, e: posefuse.ape(g, e, downsample=0), ValueError, "downsample must be >= 1"),
    (lambda g, e: posefuse.ape(g, e, motion_filter=(1.0, -2.0)), ValueError, "motion_filter must be"),
    (lambda g, e: posefuse.ape(g, e, project_to_plane="ab"), ValueError, "ab"),
    (lambda g, e: posefuse.ape(g, e, max_time_diff=float("nan")), ValueError, "max_time_diff must be finite"),
    (lambda g, e: posefuse.rpe(g, e, delta=1.5), ValueError, "delta in frames must be an integer >= 1"),
    (lambda g, e: posefuse.rpe(g, e, delta=-1, delta_unit="m"), ValueError, "delta must be positive"),
    (lambda g, e: posefuse.rpe(g, e, delta_unit="km"), ValueError, "km"),
    (lambda g, e: posefuse.rpe(g, e, delta=1e6, delta_unit="m"), posefuse.DataError, "produced an empty index list"),
    (lambda g, e: posefuse.rpe(g, e, delta=10, delta_tol=-1), ValueError, "delta_tol must be finite and >= 0"),
    (lambda g, e: posefuse.ape(g, e, align="se3", n_to_align=10**6), posefuse.DataError,
     "--n-to-align 1000000 but only 600 poses are associated"),
    (lambda g, e: posefuse.ape(g, "est.txt"), TypeError, "incompatible function arguments"),
    (lambda g, e: posefuse.ape(g, e, align=None), TypeError, "incompatible function arguments"),
    (lambda g, e: posefuse.rpe(g, e, delta="10"), TypeError, "incompatible function arguments"),
])
def test_bad_options_raise(files, call, error, text):
    gt = posefuse.read_trajectory(str(files / "gt.txt"))
    est = posefuse.read_trajectory(str(files / "est.txt"))
    with pytest.raises(error) as e:
        call(gt, est)
    assert text in str(e.value)


def test_bad_data_raises_data_error(files, tmp_path):
    gt = posefuse.read_trajectory(str(files / "gt.txt"))
    posefuse.write_trajectory(tmp_path / "short.txt", posefuse.Trajectory(gt.stamps[:10], gt.poses[:10]), "kitti")
    with pytest.raises(posefuse.DataError, match="reference has 600 poses but estimate 10"):
        posefuse.ape(gt, posefuse.read_trajectory(str(tmp_path / "short.txt")))
    with pytest.raises(ValueError, match="needs times= for the KITTI one"):
        posefuse.ape(gt, posefuse.read_trajectory(str(files / "est.tum")))
    far = posefuse.Trajectory([1e6, 1e6 + 1], positions=np.zeros((2, 3)))
    with pytest.raises(posefuse.InvalidArgument, match="found no matching timestamps"):
        posefuse.ape(posefuse.read_trajectory(str(files / "gt.tum")), far)
    line = posefuse.Trajectory(np.arange(5.0), positions=np.c_[np.arange(5.0), np.zeros((5, 2))])
    with pytest.raises(posefuse.DataError, match="on one line, so --align se3 has no unique answer"):
        posefuse.ape(line, line, align="se3")


# Real recordings: the same numbers as the program (the JSON text equal).
def test_kitti06_stereo_ape_and_rpe(kitti06, program, tmp_path):
    gt, est = str(kitti06 / "groundtruth.txt"), str(kitti06 / "orbslam2_stereo.txt")
    g, e = posefuse.read_trajectory(gt), posefuse.read_trajectory(est)
    r = posefuse.ape(g, e, align="se3")
    assert r.to_json() == both(program, tmp_path, gt, est, ["--align", "se3"])
    assert r.count == 1101 and round(r.rmse, 6) == 0.750409  # evaluate_trajectory's documented figure
    r = posefuse.rpe(g, e, delta=100, delta_unit="m", all_pairs=True)
    assert r.to_json() == both(program, tmp_path, gt, est, ["--delta", "100", "--delta-unit", "m", "--all-pairs"],
                               ["--metric", "rpe"])


def test_kitti06_mono_sim3_with_times(kitti06, program, tmp_path):
    gt, times, est = str(kitti06 / "groundtruth.txt"), str(kitti06 / "times.txt"), str(kitti06 / "orbslam2_mono.tum")
    r = posefuse.ape(posefuse.read_trajectory(gt, times=times), posefuse.read_trajectory(est), align="sim3")
    assert r.to_json() == both(program, tmp_path, gt, est, ["--times", times, "--align", "sim3"])
    assert round(r.scale, 6) == 24.841695


def test_euroc_v101_ape_and_rpe(euroc_v101, program, tmp_path):
    gt, est = str(euroc_v101 / "groundtruth.tum"), str(euroc_v101 / "groundtruth_20hz.csv")
    g, e = posefuse.read_trajectory(gt), posefuse.read_trajectory(est)
    assert g.format == "tum" and e.format == "euroc"
    r = posefuse.ape(g, e, align="se3")
    assert r.to_json() == both(program, tmp_path, gt, est, ["--align", "se3"])
    r = posefuse.rpe(g, e, delta=1, delta_unit="m", pose_relation="angle_deg", align="se3")
    assert r.to_json() == both(program, tmp_path, gt, est,
                               ["--delta", "1", "--delta-unit", "m", "--pose-relation", "angle_deg", "--align", "se3"],
                               ["--metric", "rpe"])


def test_a_result_keeps_its_trajectories_alive(files):
    # Frame by frame, a Result uses the trajectories' own poses (no copy).
    gt = posefuse.read_trajectory(str(files / "gt.txt"))
    est = posefuse.read_trajectory(str(files / "est.txt"))
    expected = np.array(gt.positions)
    r = posefuse.ape(gt, est, align="se3")
    del gt, est
    import gc
    gc.collect()
    assert np.array_equal(r.ref.positions, expected)
    assert json.loads(r.to_json())["stamps_s"][-1] == 599.0
