// Maps (vio/vio_map.hpp, LoopClosure::to_map / add_map): save -> load is
// exact; a reloaded map relocalises a new session exactly as the map in
// memory does; two maps merge through a loop; every malformation of a map
// file is a file:line error.
#include <catch2/catch.hpp>

#include <set>

#include <posefuse/vio/loop_closure.hpp>
#include <posefuse/vio/vio_map.hpp>

#include "support/io_error.hpp"
#include "support/run_program.hpp"
#include "support/temp_dir.hpp"
#include "vio/loop_fixture.hpp"

using posefuse::LoopCandidate;
using posefuse::LoopClosure;
using posefuse::LoopResult;
using posefuse::LoopStatus;
using posefuse::SE3d;
using posefuse::VioMap;
using posefuse::test::LoopScene;
using posefuse::test::ns;

namespace {

// The first lap mapped without drift: the map's frame is the truth's.
VioMap first_lap_map(const LoopScene& scene) {
  LoopClosure lc;
  std::uint64_t seed = 1;
  for (const double t : posefuse::test::keyframe_times(0, 20)) (void)lc.add_keyframe(scene.record(t, {}, seed++));
  return lc.to_map();
}

// A second session over the second lap, in its own odometry frame (an
// offset of 0.5 rad and (1, 2, 0.3) m plus a drift of 0.3 deg/s and 2 cm/s).
LoopScene::Drift second_session() {
  LoopScene::Drift d;
  d.yaw0 = 0.5;
  d.t0 = Eigen::Vector3d(1, 2, 0.3);
  d.yaw_rate = 0.3 * std::numbers::pi / 180.0;
  d.rate = Eigen::Vector3d(0.02, 0.01, 0);
  d.start_s = 20;
  return d;
}

struct Session {
  std::vector<double> t;
  std::vector<SE3d> output;  // odometry moved by the correction known at the time
  std::vector<LoopResult> results;
  std::vector<SE3d> final_poses;
};

// Localises the second session in `map`: candidates every 2 s to the map
// keyframe 20 s earlier (same place).
Session localise(const LoopScene& scene, const VioMap& map) {
  LoopClosure lc;
  (void)lc.add_map(map, /*fixed=*/true);
  Session s;
  s.t = posefuse::test::keyframe_times(20, 30);
  std::vector<std::int64_t> ids;
  std::uint64_t seed = 500;
  for (const double t : s.t) {
    const posefuse::KeyframeRecord r = scene.record(t, second_session(), seed++);
    s.output.push_back(lc.correction().apply(r.T_w_b));
    ids.push_back(lc.add_keyframe(r));
    if (std::fmod(t, 2.0) == 0.5) s.results.push_back(lc.add_loop(LoopCandidate{ns(t), ns(t - 20), 0}));
  }
  for (const std::int64_t id : ids) s.final_poses.push_back(lc.corrected_pose(id));
  return s;
}

bool same(const SE3d& a, const SE3d& b) {
  return a.translation() == b.translation() && a.so3().quaternion().coeffs() == b.so3().quaternion().coeffs();
}

}  // namespace

TEST_CASE("vio map: save and load are exact", "[vio][map]") {
  const LoopScene scene;
  const VioMap m = first_lap_map(scene);
  posefuse::test::TempDir dir("viomap");
  const auto file = dir.path() / "map.txt";
  posefuse::save_vio_map(file, m);
  const VioMap l = posefuse::load_vio_map(file);
  REQUIRE(l.keyframes.size() == m.keyframes.size());
  REQUIRE(l.edges.size() == m.edges.size());
  for (std::size_t k = 0; k < m.keyframes.size(); ++k) {
    const auto &a = m.keyframes[k], &b = l.keyframes[k];
    CHECK(a.id == b.id);
    CHECK(a.sequence == b.sequence);
    CHECK(a.t_ns == b.t_ns);
    CHECK(a.fixed == b.fixed);
    CHECK((a.T_w_b.p == b.T_w_b.p && a.T_w_b.q.coeffs() == b.T_w_b.q.coeffs()));
    CHECK((a.T_b_c.p == b.T_b_c.p && a.T_b_c.q.coeffs() == b.T_b_c.q.coeffs()));
    CHECK((a.pose.p == b.pose.p && a.pose.yaw == b.pose.yaw && a.pose.pitch == b.pose.pitch &&
           a.pose.roll == b.pose.roll));
    REQUIRE(a.features.size() == b.features.size());
    for (std::size_t i = 0; i < a.features.size(); ++i) {
      CHECK(a.features[i].id == b.features[i].id);
      CHECK(a.features[i].m == b.features[i].m);
      CHECK(a.features[i].has_point == b.features[i].has_point);
      CHECK(a.features[i].p_w == b.features[i].p_w);
    }
  }
  for (std::size_t e = 0; e < m.edges.size(); ++e) {
    CHECK(m.edges[e].kind == l.edges[e].kind);
    CHECK(m.edges[e].edge.dp == l.edges[e].edge.dp);
    CHECK(m.edges[e].edge.dyaw == l.edges[e].edge.dyaw);
    CHECK(m.edges[e].edge.information == l.edges[e].edge.information);
  }
  const auto again = dir.path() / "again.txt";
  posefuse::save_vio_map(again, l);
  CHECK(posefuse::test::slurp(file) == posefuse::test::slurp(again));
}

TEST_CASE("vio map: a reloaded map relocalises a new session as the map in memory does", "[vio][map]") {
  const LoopScene scene;
  const VioMap m = first_lap_map(scene);
  posefuse::test::TempDir dir("viomap");
  posefuse::save_vio_map(dir.path() / "map.txt", m);
  const Session a = localise(scene, m);
  const Session b = localise(scene, posefuse::load_vio_map(dir.path() / "map.txt"));
  REQUIRE(a.results.size() == 5);
  for (std::size_t k = 0; k < a.results.size(); ++k) {
    INFO(a.results[k].reason);
    CHECK(a.results[k].status == LoopStatus::kAccepted);
    CHECK(b.results[k].status == a.results[k].status);
    CHECK(b.results[k].inliers == a.results[k].inliers);
  }
  CHECK(a.results.front().merged);
  for (std::size_t k = 0; k < a.final_poses.size(); ++k) {
    CHECK(same(a.final_poses[k], b.final_poses[k]));
    CHECK(same(a.output[k], b.output[k]));
  }
  // Before the first loop the session is in its own frame (metres off);
  // after it, in the map's (the truth's) within centimetres.
  const double before = posefuse::test::max_error({a.t.front()}, {a.output.front()});
  const double after = posefuse::test::max_error(a.t, a.final_poses);
  INFO("before " << before << " m, after " << after << " m");
  CHECK(before > 1.0);
  CHECK(after < 0.05);  // measured 0.012 m
}

TEST_CASE("vio map: two maps merge through a loop between them", "[vio][map]") {
  const LoopScene scene;
  const VioMap first = first_lap_map(scene);
  LoopClosure s2;
  std::uint64_t seed = 900;
  for (const double t : posefuse::test::keyframe_times(20, 30)) (void)s2.add_keyframe(scene.record(t, second_session(), seed++));
  posefuse::test::TempDir dir("viomap");
  posefuse::save_vio_map(dir.path() / "a.txt", first);
  posefuse::save_vio_map(dir.path() / "b.txt", s2.to_map());
  LoopClosure lc;
  (void)lc.add_map(posefuse::load_vio_map(dir.path() / "a.txt"));
  const std::int64_t b0 = lc.add_map(posefuse::load_vio_map(dir.path() / "b.txt"));
  CHECK(lc.sequences() == 2);
  const LoopResult r = lc.add_loop(LoopCandidate{ns(25.0), ns(5.0), 0});
  INFO(r.reason);
  REQUIRE(r.status == LoopStatus::kAccepted);
  CHECK(r.merged);
  const VioMap merged = lc.to_map();
  CHECK(merged.keyframes.size() == first.keyframes.size() + 40);
  CHECK(merged.edges.size() == first.edges.size() + 39 + 1);
  std::set<std::int64_t> ids;
  for (const auto& k : merged.keyframes) ids.insert(k.id);
  CHECK(ids.size() == merged.keyframes.size());
  // One fixed node: the first map's anchor; the second map's was released.
  int fixed = 0;
  for (const auto& k : merged.keyframes) fixed += k.fixed ? 1 : 0;
  CHECK(fixed == 1);
  // The second session's keyframes in the first map's frame (the truth's).
  std::vector<double> t;
  std::vector<SE3d> poses;
  for (std::int64_t id = b0; id < b0 + 40; ++id) {
    t.push_back(double(lc.keyframe(id).record.t_ns) * 1e-9);
    poses.push_back(lc.corrected_pose(id));
  }
  const double err = posefuse::test::max_error(t, poses);
  INFO("largest error of the merged session " << err << " m");
  CHECK(err < 0.15);  // one loop at 25 s; the session's own drift over 5 s on either side remains
}

TEST_CASE("vio map: malformed files are file:line errors", "[vio][map]") {
  posefuse::test::TempDir dir("viomap");
  const std::string kf0 = "keyframe 0 0 100 0 0 0 1 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 1\n";
  const std::string kf1 = "keyframe 1 0 200 1 0 0 1 0 0 0 0 0 0 1 0 0 0 1 0 0 0 0 0 0\n";
  const std::string info = " 100 0 0 0 100 0 0 100 0 1e4";
  const std::string head = "posefuse_vio_map 1\n";
  const struct {
    std::string text;
    std::string expected;
  } cases[] = {
      {"keyframe 0 0 100\n", ":1: expected the header 'posefuse_vio_map 1'"},
      {"posefuse_vio_map 2\n", ":1: unsupported map version '2'"},
      {head + "node 1\n", ":2: unknown record 'node'"},
      {head + "keyframe 0 0 100 0 0 0 1 0 0 0\n", ":2: a keyframe record has 25 fields, found 11"},
      {head + "keyframe x 0 100 0 0 0 1 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 1\n", ":2: cannot parse 'x' as a keyframe id"},
      {head + "keyframe 0 -1 100 0 0 0 1 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 1\n", ":2: the sequence number -1 is negative"},
      {head + "keyframe 0 0 100 0 0 0 2 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 1\n", ":2: the quaternion in columns 8-11 has norm 2"},
      {head + "keyframe 0 0 100 0 0 nan 1 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 1\n", ":2: non-finite value 'nan' in column 7"},
      {head + "keyframe 0 0 100 0 0 0 1 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 2\n", ":2: the fixed flag is '2'"},
      {head + kf0 + kf0, ":3: keyframe id 0 is defined twice"},
      {head + "feature 0 5 0.1 0.2\n" + kf0, ":2: its keyframe 0 is not defined above"},
      {head + kf0 + "feature 0 5 0.1 0.2 1 2\n", ":3: a feature record has 5 or 8 fields, found 7"},
      {head + kf0 + "feature 0 5 0.1 0.2\nfeature 0 5 0.3 0.2\n", ":4: feature 5 appears twice in keyframe 0"},
      {head + kf0 + "feature 0 -5 0.1 0.2\n", ":3: cannot parse '-5' as a feature id"},
      {head + kf0 + kf1 + "edge odometry 0 1 1 0 0 0" + info + " none 1\n", ":4: unknown edge kind 'odometry'"},
      {head + kf0 + kf1 + "edge loop 0 7 1 0 0 0" + info + " none 1\n", ":4: the edge's second keyframe 7 is not defined above"},
      {head + kf0 + kf1 + "edge loop 1 1 1 0 0 0" + info + " none 1\n", ":4: the edge joins keyframe 1 to itself"},
      {head + kf0 + kf1 + "edge loop 0 1 1 0 0 0 -1 0 0 0 1 0 0 1 0 1 none 1\n", ":4: the information matrix is not positive semi-definite"},
      {head + kf0 + kf1 + "edge loop 0 1 1 0 0 0" + info + " tukey 1\n", ":4: unknown loss 'tukey'"},
      {head + kf0 + kf1 + "edge loop 0 1 1 0 0 0" + info + " cauchy 0\n", ":4: the loss scale must be > 0"},
      {head + kf0 + kf1 + "edge loop 0 1 1 0 0 0" + info + "\n", ":4: an edge record has 20 fields, found 18"},
  };
  int k = 0;
  for (const auto& c : cases) {
    INFO(c.text);
    const auto f = dir.write("bad" + std::to_string(k++) + ".txt", c.text);
    const std::string what = posefuse::test::io_error_of([&] { (void)posefuse::load_vio_map(f); });
    CHECK_THAT(what, Catch::StartsWith(f.string()) && Catch::Contains(c.expected));
  }
  const auto empty = dir.write("empty.txt", "# nothing\n");
  CHECK_THAT(posefuse::test::io_error_of([&] { (void)posefuse::load_vio_map(empty); }),
             Catch::Contains("empty.txt: empty file"));
  const auto none = dir.write("none.txt", head);
  CHECK_THAT(posefuse::test::io_error_of([&] { (void)posefuse::load_vio_map(none); }),
             Catch::Contains("none.txt: the map has no keyframe"));
  // A good file with every record kind loads.
  const auto good = dir.write("good.txt", head + kf0 + kf1 + "feature 0 5 0.1 0.2 1 2 3\nfeature 1 5 0.1 0.2\n" +
                                              "edge sequential 0 1 1 0 0 0" + info + " none 1\n");
  const VioMap m = posefuse::load_vio_map(good);
  CHECK(m.keyframes.size() == 2);
  CHECK(m.keyframes[0].features[0].has_point);
  CHECK_FALSE(m.keyframes[1].features[0].has_point);
  CHECK(m.edges.size() == 1);
}
