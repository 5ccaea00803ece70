#!/usr/bin/python3
"""Starts of visual_inertial_odometry in the middle of a EuRoC sequence.

For each cut time (seconds after the sequence's first IMU sample), the
tracks, the IMU and the ground truth are cut there, the estimator is run for
--duration seconds of frames with its default start (--init auto), and one
table row is printed: time from the cut to the first estimated frame, how the
start was made, its gravity and scale errors against the ground truth, the
failures, and the position + yaw APE of the frames estimated.

  scripts/vio-starts.py --program build/examples/visual_inertial_odometry \\
      --data /path/to/euroc/V1_01_easy --tracks v101_tracks.csv [--imu imu.csv]

Cut files are written to a temporary directory and removed.
"""
import argparse
import json
import pathlib
import subprocess
import sys
import tempfile


def cut(src: pathlib.Path, dst: pathlib.Path, t_ns: int) -> None:
    with open(src) as f, open(dst, "w") as g:
        for line in f:
            head = line.split(",", 1)[0]
            if not head.isdigit() or int(head) >= t_ns:
                g.write(line)


def first_stamp(path: pathlib.Path) -> int:
    with open(path) as f:
        for line in f:
            head = line.split(",", 1)[0]
            if head.isdigit():
                return int(head)
    sys.exit(f"{path}: no data row")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--program", required=True, type=pathlib.Path)
    ap.add_argument("--data", required=True, type=pathlib.Path, help="EuRoC folder with imu0.csv, "
                    "groundtruth_20hz.csv, cam0_sensor.yaml")
    ap.add_argument("--tracks", required=True, type=pathlib.Path)
    ap.add_argument("--imu", type=pathlib.Path, help="IMU csv (default: the folder's imu0.csv)")
    ap.add_argument("--first", type=float, default=10.0, help="first cut (s)")
    ap.add_argument("--step", type=float, default=5.0, help="between cuts (s)")
    ap.add_argument("--count", type=int, default=20)
    ap.add_argument("--duration", type=float, default=30.0, help="seconds of frames run after each cut")
    ap.add_argument("--rate", type=float, default=20.0, help="frame rate (Hz)")
    a = ap.parse_args()
    imu = a.imu or a.data / "imu0.csv"
    gt = a.data / "groundtruth_20hz.csv"
    t0 = first_stamp(imu)
    print("| cut (s) | start after (s) | how | gravity error (deg) | scale error (%) | failures | APE pos+yaw (m) |")
    print("|---|---|---|---|---|---|---|")
    ok = 0
    with tempfile.TemporaryDirectory() as tmp:
        d = pathlib.Path(tmp)
        for i in range(a.count):
            c = a.first + i * a.step
            t = t0 + int(round(c * 1e9))
            for src, name in ((a.tracks, "tracks.csv"), (imu, "imu.csv"), (gt, "gt.csv")):
                cut(src, d / name, t)
            r = subprocess.run([str(a.program), "--tracks", str(d / "tracks.csv"), "--camera",
                                str(a.data / "cam0_sensor.yaml"), "--imu", str(d / "imu.csv"), "--groundtruth",
                                str(d / "gt.csv"), "--max-frames", str(int(a.duration * a.rate)), "--json"],
                               capture_output=True, text=True)
            if r.returncode != 0:
                print(f"| {c:g} | - | {r.stderr.strip().splitlines()[-1] if r.stderr else 'failed'} | | | | |")
                continue
            j = json.loads(r.stdout)
            s = j["start_details"][0]
            after = s["t_s"] - t / 1e9
            g = s["gravity_error_deg"]
            sc = s["scale_error"]
            how = s["how"].split(" (")[0]
            fmt = lambda v, k=1.0, p=2: "-" if v is None else f"{k * v:.{p}f}"
            print(f"| {c:g} | {after:.2f} | {how} | {fmt(g)} | {fmt(sc, 100.0, 1)} | {len(j['failures'])} | "
                  f"{j['ape_posyaw_rmse_m']:.3f} |")
            good = (after <= 2.0 and g is not None and g <= 0.5 and sc is not None and abs(sc) <= 0.02 and
                    j["ape_posyaw_rmse_m"] <= 0.10)
            ok += good
    print(f"\n{ok} of {a.count} starts within 2 s, gravity <= 0.5 deg, scale within 2 %, APE <= 0.10 m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
