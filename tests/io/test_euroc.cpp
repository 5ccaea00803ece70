// EuRoC csv readers (io/euroc.hpp): layout, 8- and 17-column ground truth,
// and strictness (file:line errors for every malformed line); the real
// V1_01_easy files when present (skipped visibly otherwise).
#include <catch2/catch.hpp>

#include <limits>
#include <string>

#include <posefuse/io/euroc.hpp>

#include "support/data_path.hpp"
#include "support/io_error.hpp"
#include "support/temp_dir.hpp"

namespace {

const char* kImuHeader =
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";

using posefuse::test::io_error_of;

}  // namespace

TEST_CASE("EuRoC: IMU csv reads stamps, rates and specific forces", "[io][euroc]") {
  posefuse::test::TempDir dir("euroc");
  const auto f = dir.write("imu.csv", std::string(kImuHeader) +
                                          "1403715273262142976,-0.002,0.017,0.077,9.08,0.13,-3.69\n"
                                          "\n"
                                          "1403715273267142912, 0.001 ,0.0195,0.078,9.07,0.12,-3.70\r\n");
  const std::vector<posefuse::ImuSample> s = posefuse::read_euroc_imu(f);
  REQUIRE(s.size() == 2);
  CHECK(s[0].t_ns == 1403715273262142976);
  CHECK(s[1].t_ns == 1403715273267142912);
  CHECK(s[0].gyro_radps == Eigen::Vector3d(-0.002, 0.017, 0.077));
  CHECK(s[0].accel_mps2 == Eigen::Vector3d(9.08, 0.13, -3.69));
  CHECK(s[1].gyro_radps.x() == 0.001);
}

TEST_CASE("EuRoC: malformed IMU files give file:line errors", "[io][euroc]") {
  posefuse::test::TempDir dir("euroc");
  const std::string good = "1000,0,0,0,0,0,9.81\n";
  const auto bad = [&](const std::string& line) {
    return io_error_of([&] {
      (void)posefuse::read_euroc_imu(dir.write("bad.csv", std::string(kImuHeader) + good + line));
    });
  };
  CHECK_THAT(bad("2000,0,0,0,0,0\n"), Catch::Contains("bad.csv:3: expected 7 comma-separated fields"));
  CHECK_THAT(bad("2000,0,0,nan,0,0,9.81\n"), Catch::Contains("bad.csv:3: non-finite value 'nan' in column 4"));
  CHECK_THAT(bad("2000,0,0,x,0,0,9.81\n"), Catch::Contains("bad.csv:3: cannot parse 'x' in column 4"));
  CHECK_THAT(bad("2000.5,0,0,0,0,0,9.81\n"), Catch::Contains("bad.csv:3: cannot parse '2000.5' in column 1"));
  CHECK_THAT(bad("99999999999999999999,0,0,0,0,0,9.81\n"), Catch::Contains("bad.csv:3: timestamp"));
  CHECK_THAT(bad("1000,0,0,0,0,0,9.81\n"), Catch::Contains("bad.csv:3: timestamp 1000 repeats the previous one (1000 on line 2)"));
  CHECK_THAT(bad("999,0,0,0,0,0,9.81\n"), Catch::Contains("bad.csv:3: timestamp 999 is earlier than the previous one"));
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu(dir.write("empty.csv", kImuHeader)); }),
             Catch::Contains("empty.csv: no IMU samples"));
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu(dir.path() / "missing.csv"); }),
             Catch::Contains("missing.csv"));
}

TEST_CASE("EuRoC: IMU readings beyond the stated, configurable bounds are refused", "[io][euroc]") {
  posefuse::test::TempDir dir("euroc");
  const auto file = [&](const std::string& reading) {
    return dir.write("imu.csv", std::string(kImuHeader) + "1000,0,0,0,0,0,9.81\n2000," + reading + "\n");
  };
  // Defaults: 50 rad/s and 500 m/s^2 per axis (EuRoC's ADIS16448 saturates
  // at 17.5 rad/s and 176 m/s^2).
  CHECK(posefuse::kMaxAbsAngularRate == 50.0);
  CHECK(posefuse::kMaxAbsSpecificForce == 500.0);
  CHECK_NOTHROW(posefuse::read_euroc_imu(file("-50,0,0,0,0,-500")));
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu(file("9000,0,0,0,0,9.81")); }),
             Catch::Contains("imu.csv:3: angular rate of magnitude 9000 rad/s is beyond the physical bound 50 rad/s"));
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu(file("0,0,0,0,1e308,9.81")); }),
             Catch::Contains("imu.csv:3: specific force of magnitude 1e+308 m/s^2 is beyond the physical bound 500"));
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu(file("0,0,50.000001,0,0,9.81")); }),
             Catch::Contains("imu.csv:3: angular rate of magnitude 50 rad/s is beyond"));
  // A sensor of a wider range: the bounds are options.
  posefuse::ImuReadOptions wide;
  wide.max_abs_angular_rate = 1e4;
  wide.max_abs_specific_force = 2000;
  const auto s = posefuse::read_euroc_imu(file("9000,0,0,0,0,1500"), wide);
  REQUIRE(s.size() == 2);
  CHECK(s[1].gyro_radps.x() == 9000);
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu(file("0,0,0,0,0,2001"), wide); }),
             Catch::Contains("beyond the physical bound 2000 m/s^2"));
  // Bounds beyond what pre-integration can hold are refused.
  for (const double bad : {0.0, -1.0, 2e4, std::numeric_limits<double>::quiet_NaN()}) {
    posefuse::ImuReadOptions o;
    o.max_abs_angular_rate = bad;
    CHECK_THROWS_AS(posefuse::read_euroc_imu(file("0,0,0,0,0,9.81"), o), posefuse::invalid_argument);
  }
  posefuse::ImuReadOptions o;
  o.max_abs_specific_force = 1e8;
  CHECK_THROWS_AS(posefuse::read_euroc_imu(file("0,0,0,0,0,9.81"), o), posefuse::invalid_argument);
}

TEST_CASE("EuRoC: ground truth with 8 or 17 columns", "[io][euroc]") {
  posefuse::test::TempDir dir("euroc");
  const auto f8 = dir.write("gt8.csv",
                            "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], "
                            "q_RS_x [], q_RS_y [], q_RS_z []\n"
                            "1000,1,2,3,1,0,0,0\n"
                            "2000,1.5,2,3,0,0,0,1\n");
  const posefuse::EurocGroundTruth g8 = posefuse::read_euroc_groundtruth(f8);
  REQUIRE(g8.size() == 2);
  CHECK_FALSE(g8.has_velocity_and_biases());
  CHECK(g8.t_ns[1] == 2000);
  CHECK(g8.trajectory.t_s[1] == posefuse::seconds_from_ns(2000));
  CHECK(g8.trajectory.poses[0].translation() == Eigen::Vector3d(1, 2, 3));
  CHECK(g8.trajectory.poses[1].linear().isApprox(
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
  const auto f17 = dir.write("gt17.csv",
                             "#time(ns),px,py,pz,qw,qx,qy,qz,vx,vy,vz,bwx,bwy,bwz,bax,bay,baz\n"
                             "1000,1,2,3,1,0,0,0,0.1,0.2,0.3,0.01,0.02,0.03,-0.1,-0.2,-0.3\n");
  const posefuse::EurocGroundTruth g17 = posefuse::read_euroc_groundtruth(f17);
  REQUIRE(g17.has_velocity_and_biases());
  CHECK((*g17.velocity)[0] == Eigen::Vector3d(0.1, 0.2, 0.3));
  CHECK((*g17.gyro_bias)[0] == Eigen::Vector3d(0.01, 0.02, 0.03));
  CHECK((*g17.accel_bias)[0] == Eigen::Vector3d(-0.1, -0.2, -0.3));

  const auto bad = [&](const std::string& text) {
    return io_error_of([&] { (void)posefuse::read_euroc_groundtruth(dir.write("bad.csv", text)); });
  };
  CHECK_THAT(bad("1000,1,2,3,1,0,0\n"), Catch::Contains("bad.csv:1: expected 8 fields"));
  CHECK_THAT(bad("1000,1,2,3,1,0,0,0\n2000,1,2,3,1,0,0,0,0\n"),
             Catch::Contains("bad.csv:2: expected 8 comma-separated fields"));
  CHECK_THAT(bad("1000,1,2,3,0,0,0,0\n"), Catch::Contains("bad.csv:1: quaternion has zero norm"));
  CHECK_THAT(bad("1000,1,2,3,1.5,0,0,0\n"), Catch::Contains("bad.csv:1: quaternion norm"));
  CHECK_THAT(bad("1000,1,2,inf,1,0,0,0\n"), Catch::Contains("bad.csv:1: non-finite value"));
  CHECK_THAT(bad("2000,1,2,3,1,0,0,0\n1000,1,2,3,1,0,0,0\n"),
             Catch::Contains("bad.csv:2: timestamp 1000 is earlier than the previous one (2000 on line 1)"));
}

TEST_CASE("EuRoC: the real V1_01_easy files", "[io][euroc][data]") {
  POSEFUSE_REQUIRE_DATASET(d, "euroc/V1_01_easy");
  const std::vector<posefuse::ImuSample> imu = posefuse::read_euroc_imu(d / "imu0.csv");
  CHECK(imu.size() == 29120);
  const posefuse::EurocGroundTruth gt = posefuse::read_euroc_groundtruth(d / "groundtruth_20hz.csv");
  CHECK(gt.has_velocity_and_biases());
  CHECK(gt.size() > 2800);
  CHECK(gt.t_ns.front() >= imu.front().t_ns);
}
