// Writes the seed corpora of the fuzz harnesses: make_seed_corpus <dir>
// creates <dir>/<harness>/<seed> files, a few valid inputs (written with the
// library's own writers, and the programs' JSON writer for compare_results'
// saved results) and edge cases per format. It checks what it writes: every
// seed named valid_* must be accepted by the reader and every seed named
// bad_* rejected with posefuse::io_error (compare_results' reader:
// posefuse::apps::data_error), so a format change
// that invalidates the seeds fails the build instead of silently starving
// the fuzzers. Nothing is copied from the real datasets.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/euroc.hpp>
#include <posefuse/io/g2o.hpp>
#include <posefuse/io/kitti.hpp>
#include <posefuse/io/robot_log.hpp>
#include <posefuse/io/tum.hpp>

#include "compare_results_reader.hpp"
#include "fuzz_support.hpp"

namespace fs = std::filesystem;
using posefuse_fuzz::ByteWriter;
using posefuse_fuzz::join_files;

namespace {

int g_errors = 0;

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void put(const fs::path& dir, const std::string& name, const std::string& bytes) {
  fs::create_directories(dir);
  std::ofstream out(dir / name, std::ios::binary | std::ios::trunc);
  out << bytes;
  if (!out) {
    std::fprintf(stderr, "make_seed_corpus: cannot write %s\n", (dir / name).string().c_str());
    ++g_errors;
  }
}

/// Checks that a seed `<harness>/<seed>` is accepted (valid_*) or rejected
/// (bad_*) by `read`.
void expect(const std::string& name, const std::function<void()>& read) {
  const bool valid = name.find("/valid_") != std::string::npos;
  std::string why;
  bool accepted = true;
  try {
    read();
  } catch (const posefuse::io_error& e) {
    accepted = false;
    why = e.what();
  }
  if (accepted != valid) {
    std::fprintf(stderr, "make_seed_corpus: seed %s was %s%s%s\n", name.c_str(),
                 accepted ? "accepted" : "rejected", why.empty() ? "" : ": ", why.c_str());
    ++g_errors;
  }
}

// --- trajectories ------------------------------------------------------------

/// A short drive on KITTI's road plane (x right, y down, z forward): yaw about y.
posefuse::Trajectory drive(int n) {
  posefuse::Trajectory t;
  for (int k = 0; k < n; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.3 * k * k / 10.0, -0.01 * k, 1.2 * k);
    t.push_back(1317384506.4 + 0.1036 * k, T);
  }
  return t;
}

void kitti_seeds(const fs::path& out, const fs::path& tmp) {
  const fs::path dir = out / "fuzz_kitti";
  const fs::path tdir = out / "fuzz_kitti_times";
  const posefuse::Trajectory t = drive(6);
  posefuse::write_kitti(tmp / "poses.txt", t);
  posefuse::write_kitti_times(tmp / "times.txt", t);
  const std::string poses = slurp(tmp / "poses.txt");
  const std::string times = slurp(tmp / "times.txt");
  const std::string identity = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const auto seed = [&](const std::string& name, const std::string& p,
                        const std::string* s = nullptr) {
    const std::string bytes = s ? join_files({p, *s}) : p;
    put(dir, name, bytes);
    expect("fuzz_kitti/" + name, [&] {
      posefuse_fuzz::write_bytes(tmp / "p.txt", p);
      if (s) {
        posefuse_fuzz::write_bytes(tmp / "s.txt", *s);
        (void)posefuse::read_kitti(tmp / "p.txt", tmp / "s.txt");
      } else {
        (void)posefuse::read_kitti(tmp / "p.txt");
      }
    });
  };
  seed("valid_written", poses);
  seed("valid_written_with_times", poses, &times);
  seed("bad_empty", "");
  seed("valid_comments_crlf_signs",
       "# KITTI poses\r\n\r\n+1 0 0 +0.5 0 1 0 -2e-1 0 0 1 1E2\r\n   \r\n" + identity);
  // Rounded to 6 digits as real files are: re-orthonormalised on reading.
  seed("valid_rounded_rotation",
       "0.998750 0 0.049979 1.5 0 1 0 0 -0.049979 0 0.998750 3.25\n" + identity);
  const std::string two = identity + identity;
  const std::string two_times = "0\n0.1\n";
  seed("valid_two_with_times", two, &two_times);
  seed("bad_reflection", "-1 0 0 0 0 1 0 0 0 0 1 0\n");
  seed("bad_not_orthonormal", "1 0.1 0 0 0 1 0 0 0 0 1 0\n");
  seed("bad_eleven_numbers", "1 0 0 0 0 1 0 0 0 0 1\n");
  seed("bad_nan", "1 0 0 nan 0 1 0 0 0 0 1 0\n");
  seed("bad_out_of_range", "1 0 0 1e999 0 1 0 0 0 0 1 0\n");
  seed("bad_token", "1 0 0 0x1p3 0 1 0 0 0 0 1 0\n");
  const std::string three_times = "0\n0.1\n0.2\n";
  seed("bad_more_times_than_poses", two, &three_times);
  const std::string one_time = "0\n";
  seed("bad_fewer_times_than_poses", two, &one_time);
  const std::string repeated = "0\n0\n";
  seed("bad_repeated_time", two, &repeated);

  const auto tseed = [&](const std::string& name, const std::string& s) {
    put(tdir, name, s);
    expect("fuzz_kitti_times/" + name, [&] {
      posefuse_fuzz::write_bytes(tmp / "s.txt", s);
      (void)posefuse::read_kitti_times(tmp / "s.txt");
    });
  };
  tseed("valid_written", times);
  tseed("valid_scientific_crlf", "# stamps\r\n0.000000e+00\r\n1.036000e-01\r\n+2.07e-1\r\n");
  tseed("bad_empty", "");
  tseed("bad_equal", "1\n1\n");
  tseed("bad_two_numbers", "1 2\n");
  tseed("bad_inf", "inf\n");
}

void tum_seeds(const fs::path& out, const fs::path& tmp) {
  const fs::path dir = out / "fuzz_tum";
  posefuse::write_tum(tmp / "t.tum", drive(6));
  const auto seed = [&](const std::string& name, const std::string& s) {
    put(dir, name, s);
    expect("fuzz_tum/" + name, [&] {
      posefuse_fuzz::write_bytes(tmp / "s.tum", s);
      (void)posefuse::read_tum(tmp / "s.tum");
    });
  };
  seed("valid_written", slurp(tmp / "t.tum"));
  seed("valid_unnormalised_negative_w", "1.5 1 2 3 0 0 0 -1.0004\r\n1.6 1 2 3 0.70710678 0 0 0.70710678\n");
  seed("bad_empty", "# nothing\n");
  seed("bad_zero_quaternion", "0 0 0 0 0 0 0 0\n");
  seed("bad_far_from_unit", "0 0 0 0 0 0 0 1.1\n");
  seed("bad_not_increasing", "1 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n");
  seed("bad_seven_numbers", "1 0 0 0 0 0 1\n");
}

// --- g2o 2-D graphs and 4-DoF loop edges ----------------------------------------

void g2o_seeds(const fs::path& out, const fs::path& tmp) {
  const fs::path dir = out / "fuzz_g2o";
  posefuse::G2oGraph2d g;
  for (int k = 0; k < 5; ++k) g.vertices.push_back({k, 0.5 * k, 0.1 * k, 0.2 * k, 0});
  for (int k = 0; k + 1 < 5; ++k) {
    posefuse::G2oEdgeSE2 e;
    e.from = k;
    e.to = k + 1;
    e.dx = 0.5;
    e.dy = 0.1;
    e.dtheta = 0.2;
    e.information = Eigen::Vector3d(100, 100, 400).asDiagonal();
    g.edges.push_back(e);
  }
  g.fixed.push_back(0);
  posefuse::write_g2o_2d(tmp / "g.g2o", g);
  std::vector<posefuse::LoopEdge4DofRecord> loops(2);
  loops[0].from = 10;
  loops[0].to = 150;
  loops[0].dp = Eigen::Vector3d(0.1, -0.2, 0.05);
  loops[0].dyaw = 0.3;
  loops[0].information = Eigen::Vector4d(100, 100, 100, 400).asDiagonal();
  loops[1].from = 42;
  loops[1].to = 7;
  posefuse::write_loop_edges_4dof(tmp / "l.txt", loops);
  // The first byte chooses the reader: '0' (even) the 2-D graph, '1' (odd) the loops.
  const auto seed = [&](const std::string& name, char reader, const std::string& s) {
    put(dir, name, std::string(1, reader) + s);
    expect("fuzz_g2o/" + name, [&] {
      posefuse_fuzz::write_bytes(tmp / "s.txt", s);
      if (reader == '0') (void)posefuse::read_g2o_2d(tmp / "s.txt");
      else (void)posefuse::read_loop_edges_4dof(tmp / "s.txt");
    });
  };
  seed("valid_written_graph", '0', slurp(tmp / "g.g2o"));
  seed("valid_edges_before_vertices_crlf", '0',
       "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\r\nVERTEX_SE2 1 1 0 0\r\nVERTEX_SE2 0 0 0 0\r\n");
  seed("bad_unknown_tag", '0', "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n");
  seed("bad_self_edge", '0', "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 0 1 0 0 1 0 0 1 0 1\n");
  seed("bad_missing_vertex", '0', "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 9 1 0 0 1 0 0 1 0 1\n");
  seed("bad_not_psd", '0', "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 5 0 1 0 1\n");
  seed("bad_duplicate_vertex", '0', "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n");
  seed("valid_written_loops", '1', slurp(tmp / "l.txt"));
  seed("bad_loop_fifteen_fields", '1', "10 150 0 0 0 0 100 0 0 0 100 0 0 100 0\n");
  seed("bad_loop_self", '1', "3 3 0 0 0 0 100 0 0 0 100 0 0 100 0 400\n");
  seed("bad_loop_huge_id", '1', "99999999999999999999 1 0 0 0 0 100 0 0 0 100 0 0 100 0 400\n");
}

// --- EuRoC IMU and ground truth ---------------------------------------------------

void euroc_seeds(const fs::path& out, const fs::path& tmp) {
  const fs::path dir = out / "fuzz_euroc";
  std::ostringstream imu, gt;
  imu << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
         "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  gt << "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x,v_y,v_z,bw_x,bw_y,bw_z,ba_x,ba_y,ba_z\n";
  imu.precision(17);
  gt.precision(17);
  const std::int64_t t0 = 1403715273262142976;
  for (int k = 0; k < 8; ++k) {
    const double a = 0.1 * k;
    imu << t0 + 5000000LL * k << ',' << 0.01 * k << ",-0.02,0.07," << 9.08 + 0.01 * k << ",0.13,-3.69\n";
    gt << t0 + 50000128LL * k << ',' << a << ",2.18,0.95," << std::cos(a / 2) << ",0,0," << std::sin(a / 2)
       << ",0.1,0,0,-0.002,0.02,0.077,-0.018,0.066,0.031\n";
  }
  const auto seed = [&](const std::string& name, const std::string& i, const std::string& g) {
    put(dir, name, join_files({i, g}));
    expect("fuzz_euroc/" + name, [&] {
      posefuse_fuzz::write_bytes(tmp / "i.csv", i);
      posefuse_fuzz::write_bytes(tmp / "g.csv", g);
      (void)posefuse::read_euroc_imu(tmp / "i.csv");
      (void)posefuse::read_euroc_groundtruth(tmp / "g.csv");
    });
  };
  seed("valid_generated", imu.str(), gt.str());
  seed("valid_pose_only_crlf", imu.str(),
       "1000,0,0,0,1,0,0,0\r\n2000,1,0,0,0.70710678118654757,0,0,0.70710678118654757\r\n");
  seed("bad_imu_backwards", "2000,0,0,0,0,0,9.81\n1000,0,0,0,0,0,9.81\n", gt.str());
  seed("bad_imu_nan", "1000,0,0,nan,0,0,9.81\n", gt.str());
  seed("bad_imu_six_fields", "1000,0,0,0,0,9.81\n", gt.str());
  seed("bad_gt_zero_quaternion", imu.str(), "1000,0,0,0,0,0,0,0\n");
  seed("bad_gt_field_count_changes", imu.str(), "1000,0,0,0,1,0,0,0\n2000,0,0,0,1,0,0,0,0\n");
  seed("bad_gt_stamp_overflow", imu.str(), "99999999999999999999,0,0,0,1,0,0,0\n");
}

// --- compare_results' saved results ------------------------------------------

/// A saved result as evaluate_trajectory --save-results writes it (the
/// members of its summary), through the programs' JSON writer.
std::string saved_result(bool rpe, bool nees) {
  std::ostringstream text;
  posefuse::apps::JsonWriter j(text);
  j.begin_object();
  j.member("metric", rpe ? "rpe" : "ape")
      .member("groundtruth_format", "tum")
      .member("estimate_format", "tum")
      .member("formats_detected", true)
      .member("pose_relation", rpe ? "full" : "trans_part")
      .member("unit", rpe ? "unit-less" : "m")
      .member("alignment", "se3")
      .member("scale", 1.0);
  if (rpe) j.member("delta", 1.0).member("delta_unit", "frames");
  j.member("count", std::size_t(1990)).member("rmse", 0.0421).member("mean", 0.0375).member("median", 0.0350);
  j.member("std", 0.0192).member("min", 0.0011).member("max", 0.1274).member("sse", 3.5271);
  if (nees) {
    j.member("nees_mean", 2.87).member("nees_dim", 3).member("nees_lower", 2.81).member("nees_upper", 3.19);
    j.member("nees_consistent", true);
  }
  j.end_object().finish();
  return text.str();
}

void compare_results_seeds(const fs::path& out, const fs::path& tmp) {
  const fs::path dir = out / "fuzz_compare_results";
  const auto seed = [&](const std::string& name, const std::string& s) {
    put(dir, name, s);
    const std::string label = "fuzz_compare_results/" + name;
    const bool valid = name.rfind("valid_", 0) == 0;
    std::string why;
    bool accepted = true;
    try {
      posefuse_fuzz::write_bytes(tmp / "r.json", s);
      (void)posefuse_fuzz::read_saved_result(tmp / "r.json");
    } catch (const posefuse::apps::data_error& e) {
      accepted = false;
      why = e.what();
    }
    if (accepted != valid) {
      std::fprintf(stderr, "make_seed_corpus: seed %s was %s%s%s\n", label.c_str(),
                   accepted ? "accepted" : "rejected", why.empty() ? "" : ": ", why.c_str());
      ++g_errors;
    }
  };
  const std::string ape = saved_result(false, false);
  seed("valid_ape", ape);
  seed("valid_rpe_with_nees", saved_result(true, true));
  const std::string head = R"({"metric": "ape", "pose_relation": "trans_part", "alignment": "se3", "unit": "m", )";
  const std::string stats = R"("mean": 1, "median": 1, "std": 0, "min": 1, "max": 1})";
  seed("valid_members_only", head + R"("count": 5, "rmse": 1, )" + stats);
  seed("bad_null_rmse", head + R"("count": 5, "rmse": null, )" + stats);
  seed("bad_negative_count", head + R"("count": -5, "rmse": 1, )" + stats);
  seed("bad_fraction_count", head + R"("count": 2.5, "rmse": 1, )" + stats);
  seed("bad_number_out_of_range", head + R"("count": 5, "rmse": 1e999, )" + stats);
  seed("bad_duplicate_key", head + R"("count": 5, "count": 6, "rmse": 1, )" + stats);
  seed("bad_missing_unit", R"({"metric": "ape", "pose_relation": "trans_part", "alignment": "se3", )"
                           R"("count": 5, "rmse": 1, )" + stats);
  seed("bad_string_count", head + R"("count": "5", "rmse": 1, )" + stats);
  seed("bad_trailing_comma", ape.substr(0, ape.rfind('}')) + ",}");
  seed("bad_array", "[" + ape + "]");
  seed("bad_deep", std::string(70, '[') + std::string(70, ']'));
  seed("bad_escape", head.substr(0, head.size() - 2) + R"(, "x": "\ud800"})");
  seed("bad_empty", "");
}

// --- robot log ---------------------------------------------------------------

posefuse::RobotLog small_log(bool with_truth) {
  posefuse::RobotLog log;
  log.params = {1024, 0.05, 0.3, 0.98, 0.5};
  const std::int64_t t0 = 1'700'000'000'000'000'000;
  for (int i = 0; i < 8; ++i) {
    posefuse::WheelSample w;
    w.t_ns = t0 + i * 20'000'000;
    w.ticks = {30 * i, 32 * i, 30 * i, 32 * i};
    log.wheels.push_back(w);
  }
  for (int i = 0; i < 6; ++i) {
    posefuse::ImuSample s;
    s.t_ns = t0 + 1'000'000 + i * 25'000'000;
    s.accel_mps2 = {0.02 * i, -0.01, 9.81};
    s.gyro_radps = {0.0, 0.001, 0.05};
    s.mag_uT = {22.5, -3.0, -40.25};
    log.imu.push_back(s);
  }
  const posefuse::SlamState states[4] = {posefuse::SlamState::kTracking, posefuse::SlamState::kLost,
                                         posefuse::SlamState::kReinit, posefuse::SlamState::kTracking};
  for (int i = 0; i < 4; ++i) {
    posefuse::SlamSample s;
    s.t_ns = t0 + 2'000'000 + i * 40'000'000;
    s.state = states[i];
    s.position_m = {0.01 * i, 0.002 * i, 0.0};
    s.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitZ()));
    if (s.state == posefuse::SlamState::kLost) {
      s.position_m.setConstant(std::numeric_limits<double>::quiet_NaN());
      s.orientation.coeffs().setConstant(std::numeric_limits<double>::quiet_NaN());
    }
    log.slam.push_back(s);
  }
  if (with_truth) {
    for (int i = 0; i < 4; ++i) {
      posefuse::PlanarPoseSample g;
      g.t_ns = t0 + i * 45'000'000;
      g.pose = {0.01 * i, 0.0, 0.001 * i};
      log.groundtruth.push_back(g);
    }
  }
  return log;
}

void robot_log_seeds(const fs::path& out, const fs::path& tmp) {
  const fs::path dir = out / "fuzz_robot_log";
  const char* names[5] = {"robot.txt", "wheels.csv", "imu.csv", "slam.csv", "groundtruth.csv"};
  const auto files_of = [&](const posefuse::RobotLog& log) {
    const fs::path d = tmp / "log";
    fs::remove_all(d);
    posefuse::write_robot_log(d, log);
    std::vector<std::string> files;
    for (const char* n : names) {
      if (fs::exists(d / n)) files.push_back(slurp(d / n));
    }
    return files;
  };
  const auto seed = [&](const std::string& name, const std::vector<std::string>& files) {
    put(dir, name, join_files(files));
    expect("fuzz_robot_log/" + name, [&] {
      const fs::path d = tmp / "check";
      fs::remove_all(d);
      fs::create_directories(d);
      for (std::size_t i = 0; i < files.size(); ++i) posefuse_fuzz::write_bytes(d / names[i], files[i]);
      (void)posefuse::read_robot_log(d);
    });
  };
  const std::vector<std::string> full = files_of(small_log(true));
  seed("valid_written", full);
  seed("valid_written_without_truth", files_of(small_log(false)));

  std::vector<std::string> edited = full;
  edited[0] = "ticks_per_rev = 1024  # encoder\r\nWHEEL_RADIUS_M\t0.05\ntrack_width_m 0.3\n"
              "complementary_alpha=0.98\nfuser_threshold 5e-1\n";
  edited[1] = "t_ns,fl,fr,bl,br\r\n" + full[1];
  edited[3] = "t_ns,state,x,y,z,qx,qy,qz,qw\n"
              "1700000000002000000,TRACKING,0,0,0,0,0,0,1\n"
              "1700000000042000000,lost,,,,,,,\n"
              "1700000000082000000, Reinit ,+0.02,0.004,0,0,0,0.01,0.99995\n";
  seed("valid_headers_keys_lost_row", edited);

  std::vector<std::string> bad = full;
  bad[1] = "# t_ns,fl,fr,bl,br\n1700000000000000000,0,0,0,0\n1700000000020000000,4000000,0,0,0\n";
  seed("bad_wheel_wraparound", bad);
  bad = full;
  bad[2] = "1700000000001000000,0,0,-9.81,0,0,0,0,0,0\n";
  seed("bad_imu_z_down", bad);
  bad = full;
  bad[0] = "ticks_per_rev 1024\nwheel_radius_m 0.05\ntrack_width_m 0.3\ncomplementary_alpha 1\n"
           "fuser_threshold 0.5\n";
  seed("bad_alpha_one", bad);
  seed("bad_missing_slam", {full[0], full[1], full[2]});
}

// --- EKF operations ----------------------------------------------------------
// The byte layout decoded by fuzz_ekf.cpp: choices are single bytes, numbers
// as written by ByteWriter; operations 0 reset, 1 predict, 2 update<I>,
// 3 update<I> with a gate, 4 update_with, 5 set_gate; covariance modes 0
// diagonal, 1 L L^T, 2 symmetric, 3 full.

struct Ops {
  ByteWriter w;
  Ops& b(std::uint8_t x) {
    w.byte(x);
    return *this;
  }
  Ops& n(std::initializer_list<double> v) {
    for (const double x : v) w.raw(x);
    return *this;
  }
  Ops& s(std::uint8_t i) {
    w.special(i);
    return *this;
  }
  Ops& diag(std::initializer_list<double> v) { return b(0).n(v); }
};

constexpr std::uint8_t kNaN = 30, kInf = 28, kMax = 17, kDenorm = 20, kNegOne = 3;

void ekf_seeds(const fs::path& out) {
  const fs::path dir = out / "fuzz_ekf";
  {  // constant velocity, all three position fixes
    Ops o;
    o.b(0).n({0.5}).diag({0.25}).diag({0.25, 0.25}).diag({0.25, 0.25, 1, 1});
    o.b(1).n({0.1});                                                  // predict before reset
    o.b(0).n({0, 0, 1, 0}).diag({1, 1, 4, 4});                        // reset
    o.b(1).n({0.1}).b(2).b(1).n({0.12, 0.01});                        // predict, update<1>
    o.b(2).b(1).n({0.12, 0.01});                                      // same P: memoised gain
    o.b(2).b(0).n({0.2}).b(2).b(2).n({0.2, 0.0, 1.0, 0.1});           // update<0>, update<2>
    o.b(3).b(1).n({5, 5}).b(0).n({9.21});                             // gated by NIS
    o.b(3).b(1).n({0.3, 0}).b(1).b(1);                                // functor says no
    o.b(4).b(1).b(2).n({1, 0.5, 2}).n({0.3, 0.02}).b(1);              // update_with, symmetric noise
    o.b(5).b(1).n({4}).b(5).b(0).s(kNegOne);                          // set_gate, bad gate
    o.b(1).s(kNaN).b(1).n({-0.1}).b(1).s(kInf);                       // bad dt
    o.b(0).n({0, 0, 0, 0}).b(2).n({1, 2, 3, 4, 5, 6, 7, 8, 9, 10});   // indefinite reset
    put(dir, "cv_sequence", o.w.bytes());
  }
  {  // constant velocity pushed to the limits of double
    Ops o;
    o.b(0).n({1}).diag({1}).diag({1, 1}).diag({1, 1, 1, 1});
    o.b(0).n({0, 0, 0, 0}).b(0).s(kMax).s(kMax).s(kMax).s(kMax);
    o.b(1).n({0}).b(2).b(0).n({1});
    o.b(0).n({1e300, -1e300, 0, 0}).b(0).s(kDenorm).s(kDenorm).n({1, 1});
    o.b(1).n({1e10}).b(2).b(1).n({1, 1});
    put(dir, "cv_extremes", o.w.bytes());
  }
  {  // unicycle, exact arc
    Ops o;
    o.b(1).b(1).diag({0.01, 0.001}).diag({0.04, 0.04, 0.01}).n({0.05});
    o.b(0).n({0, 0, 3.1}).diag({0.1, 0.1, 0.05});
    o.b(1).n({1.0, 0.8, 0.1}).b(2).b(0).n({0.1, 0.01, -3.1});         // wraps at +-pi
    o.b(2).b(1).n({3.13}).b(4).b(1).n({0.02}).n({-3.12}).b(1);
    o.b(4).b(0).b(1).n({0.1, 0, 0, 0.1, 0, 0.1}).n({0.1, 0, 3}).b(0).n({11.3});
    o.b(1).n({5, 100, 0.5}).b(3).b(0).n({0, 0, 0}).b(2).b(0);
    put(dir, "unicycle_sequence", o.w.bytes());
  }
  {  // unicycle, Euler
    Ops o;
    o.b(1).b(0).diag({0.04, 0.01}).diag({0.01, 0.01, 0.0025}).n({0.02});
    o.b(0).n({1, 2, -3}).diag({0, 0, 0});                             // exact belief
    o.b(1).n({0.5, 0.2, 0.05}).b(2).b(0).n({1.02, 2.0, -3.0});
    put(dir, "unicycle_euler_zero_cov", o.w.bytes());
  }
  {  // SE(2) odometry
    Ops o;
    o.b(2).n({0.02, 0.005, 0.03}).diag({0.01, 0.01, 0.0025}).n({0.05});
    o.b(0).n({0, 0, 0}).diag({0.01, 0.01, 0.01});
    o.b(1).n({0.1, 0.0, 0.02, 0.1}).b(1).n({0.1, 0.01, -0.02, 0.1});
    o.b(2).b(0).n({0.2, 0.0, 0.0}).b(2).b(1).n({0.01});
    o.b(1).n({1e8, -1e8, 7, 0}).b(2).b(0).n({1e8, 1e8, 1});
    put(dir, "se2_sequence", o.w.bytes());
  }
  {  // planar displacement (identity Jacobians)
    Ops o;
    o.b(3).diag({0.01, 0.01}).diag({0.25, 0.25});
    o.b(0).n({0, 0}).diag({1, 1});
    o.b(1).n({0.5, 0.1, 0}).b(2).b(0).n({0.6, 0.05});
    o.b(4).b(2).n({1, 0.999, 1}).n({0.5, 0.2}).b(1);                  // nearly singular noise
    o.b(3).b(0).n({1, 1}).b(2).b(1);
    put(dir, "displacement_sequence", o.w.bytes());
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seed_corpus <output folder>\n");
    return 2;
  }
  const fs::path out = argv[1];
  const posefuse_fuzz::ScratchDir tmp("seed-corpus");
  kitti_seeds(out, tmp.path());
  tum_seeds(out, tmp.path());
  g2o_seeds(out, tmp.path());
  euroc_seeds(out, tmp.path());
  compare_results_seeds(out, tmp.path());
  robot_log_seeds(out, tmp.path());
  ekf_seeds(out);
  if (g_errors > 0) {
    std::fprintf(stderr, "make_seed_corpus: %d error(s)\n", g_errors);
    return 1;
  }
  return 0;
}
