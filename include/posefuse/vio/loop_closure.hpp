#pragma once
/// @file
/// Loop closure and relocalisation for the visual-inertial odometry, after
/// VINS-Mono (Qin, Li, Shen, IEEE T-RO 2018, Sec. VII-VIII): a keyframe
/// database, geometric verification of loop candidates by PnP + RANSAC, a
/// 4-DoF pose graph (x, y, z, yaw; graph/pose_graph_4dof.hpp) and the drift
/// correction that moves the odometry's output into the corrected frame.
///
/// **Database.** Each KeyframeRecord (vio/keyframe_record.hpp, handed on by
/// the estimator when a keyframe leaves its window) becomes a node with the
/// next id; consecutive keyframes of one sequence get a *sequential* edge
/// with the odometry's relative pose (roll and pitch of every node stay the
/// odometry's). A node's initial pose is its odometry pose moved by the
/// sequence's current drift correction. Keyframes belong to sequences (one
/// per session: the live one, or maps added with add_map()); sequences
/// joined by edges form a group, and each group has one fixed node (the
/// first node of its first sequence), so the graph is always solvable.
///
/// **Candidate** (t_query, t_match), stamps of images: each stamp names the
/// keyframe nearest to it within `stamp_tolerance_s` (the query among the
/// keyframes of the newest sequence that has one that near, the match among
/// all keyframes; none → kUnknownQuery / kUnknownMatch). Query and match of
/// one sequence closer than `min_gap_s` in time → kTooCloseInTime (the
/// odometry already links them). Correspondences: each feature of the query
/// (normalised observation) whose id has a world point in the match keyframe
/// or in the `neighbour_keyframes` keyframes on either side of it in its
/// sequence (the match's own point first, then the nearest neighbour's);
/// fewer than `min_inliers` → kTooFewCorrespondences. PnP + RANSAC
/// (vio/pnp.hpp, solve_pnp_ransac) gives the query camera in the match's
/// odometry frame, hence \f$ T_{match,query} \f$ (when both are in one
/// group, the graph's relative pose is RANSAC's first hypothesis); fewer than `min_inliers`
/// inliers or a PnP failure → kPnpFailed with PnP's reason. A relative pose
/// farther than VINS-Mono's bounds (`max_relative_yaw_deg`,
/// `max_relative_distance_m`) → kImplausible.
///
/// **Loop edge.** An accepted candidate adds an edge match → query with the
/// 4-DoF part of \f$ T_{match,query} \f$: \f$ \Delta p = R_m^\top (p_q - p_m) \f$
/// (R_m the match's odometry attitude) and \f$ \Delta\psi = \psi_q - \psi_m \f$,
/// with the loop information and robust loss of the options (Cauchy by
/// default). When the query's group is not the match's, the query's whole
/// group (the match's instead when only the query's holds nodes a map
/// fixed) is first moved by the 4-DoF transform that puts the query where
/// the loop says (relocalisation in a map; merging two maps) and the two
/// groups become one. Then the graph is re-optimised (Levenberg–Marquardt).
///
/// **Drift correction** of a sequence: the 4-DoF transform
/// \f$ T_{corrected,w} \f$ (yaw \f$ \delta\psi \f$ about z, translation
/// \f$ \delta t \f$) taking its newest keyframe's odometry pose to that
/// keyframe's graph pose: \f$ R_z(\delta\psi) = R_z(\psi_{graph} - \psi_{odom}) \f$,
/// \f$ \delta t = p_{graph} - R_z(\delta\psi) p_{odom} \f$. Applied to every
/// odometry pose after it, as VINS-Mono does; the odometry itself is not
/// changed. It changes only when a loop is accepted; LoopResult reports it
/// before and after. The types (statuses, options with their defaults,
/// results, DriftCorrection) are in vio/loop_types.hpp.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/io/loop_candidates.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/vio/keyframe_record.hpp>
#include <posefuse/vio/loop_types.hpp>
#include <posefuse/vio/pnp.hpp>
#include <posefuse/vio/vio_map.hpp>

namespace posefuse {

/// The keyframe database, loop verification and 4-DoF pose graph (see the file comment).
class LoopClosure {
 public:
  /// A keyframe as the database keeps it.
  struct Keyframe {
    std::int64_t id = 0;      ///< node id
    int sequence = 0;         ///< its sequence
    KeyframeRecord record;    ///< the odometry's record (pose, extrinsic, features)
  };

  /// @throws posefuse::invalid_argument for options out of range
  explicit LoopClosure(const LoopClosureOptions& o = {}) : o_(o) {
    if (!(o.stamp_tolerance_s >= 0) || !(o.min_gap_s >= 0) || o.neighbour_keyframes < 0 || o.min_inliers < 6 ||
        !(o.sequential_sigma_m > 0) || !(o.sequential_sigma_yaw_rad > 0) || !(o.loop_sigma_m > 0) ||
        !(o.loop_sigma_yaw_rad > 0) || !(o.max_relative_yaw_deg > 0) || !(o.max_relative_distance_m > 0))
      throw invalid_argument("LoopClosure: options out of range (tolerances >= 0, sigmas > 0, min_inliers >= 6)");
    o_.pnp.min_inliers = std::max(o_.pnp.min_inliers, o_.min_inliers);
  }

  /// Starts a new live sequence: the next add_keyframe() begins it, with no
  /// edge to earlier keyframes (a new session, or after the odometry restarted).
  void start_sequence() { live_ = -1; }

  /// Adds a keyframe of the live sequence (starting one when needed) and its
  /// sequential edge; returns its node id.
  /// @throws posefuse::invalid_argument for a non-finite pose or a stamp not after the previous keyframe's
  std::int64_t add_keyframe(const KeyframeRecord& r) {
    if (!r.T_w_b.translation().allFinite() || !r.T_w_b.so3().quaternion().coeffs().allFinite())
      throw invalid_argument("LoopClosure: keyframe at " + std::to_string(r.t_ns) + " ns has a non-finite pose");
    if (live_ < 0) live_ = new_sequence();
    Sequence& s = seq_[std::size_t(live_)];
    if (!s.nodes.empty() && !(r.t_ns > kf_[s.nodes.back()].record.t_ns))
      throw invalid_argument("LoopClosure: keyframe stamps must increase within a sequence");
    const std::int64_t id = next_id_++;
    const Pose4Dof odo = pose_4dof(r.T_w_b);
    const bool anchor = s.nodes.empty();  // the first keyframe of a new live sequence fixes its group
    add_node(Keyframe{id, live_, r}, s.correction.apply(odo), anchor);
    if (anchor) anchors_.insert(id);
    if (s.nodes.size() >= 2) {
      const Keyframe& a = kf_[s.nodes[s.nodes.size() - 2]];
      graph_.add_edge(sequential_edge(a.id, a.record.T_w_b, id, r.T_w_b));
      edge_kind_.push_back(MapEdgeKind::kSequential);
    }
    return id;
  }

  /// Verifies a candidate and, when accepted, adds its loop edge and
  /// re-optimises the graph (see the file comment).
  LoopResult add_loop(const LoopCandidate& c) {
    LoopResult res = verify(c);
    if (res.status == LoopStatus::kAccepted) accept(res);
    return res;
  }

  /// add_loop() for two keyframes named by node id (no stamp look-up).
  /// @throws posefuse::invalid_argument for an unknown id
  LoopResult add_loop_between(std::int64_t query_id, std::int64_t match_id) {
    LoopResult res = verify_between(query_id, match_id);
    if (res.status == LoopStatus::kAccepted) accept(res);
    return res;
  }

  /// Verification only (the graph is not changed).
  [[nodiscard]] LoopResult verify(const LoopCandidate& c) const {
    LoopResult res;
    res.before = res.after = correction();
    const std::optional<std::int64_t> q = query_keyframe(c.t_query_ns);
    if (!q) {
      res.status = LoopStatus::kUnknownQuery;
      res.reason = "no keyframe within " + fmt(o_.stamp_tolerance_s) + " s of the query stamp " +
                   std::to_string(c.t_query_ns) + " ns";
      return res;
    }
    const std::optional<std::int64_t> m = keyframe_at(c.t_match_ns);
    if (!m) {
      res.status = LoopStatus::kUnknownMatch;
      res.query_id = *q;
      res.reason = "no keyframe within " + fmt(o_.stamp_tolerance_s) + " s of the match stamp " +
                   std::to_string(c.t_match_ns) + " ns";
      return res;
    }
    return verify_between(*q, *m);
  }

  /// verify() for two keyframes named by node id.
  /// @throws posefuse::invalid_argument for an unknown id
  [[nodiscard]] LoopResult verify_between(std::int64_t query_id, std::int64_t match_id) const {
    LoopResult res;
    res.before = res.after = correction();
    const Keyframe& q = keyframe(query_id);
    const Keyframe& m = keyframe(match_id);
    res.query_id = q.id;
    res.match_id = m.id;
    res.t_query_ns = q.record.t_ns;
    res.t_match_ns = m.record.t_ns;
    if (q.sequence == m.sequence &&
        std::abs(double(q.record.t_ns - m.record.t_ns)) * 1e-9 < o_.min_gap_s) {
      res.status = LoopStatus::kTooCloseInTime;
      res.reason = "query and match are " + fmt(std::abs(double(q.record.t_ns - m.record.t_ns)) * 1e-9) +
                   " s apart in one sequence (minimum " + fmt(o_.min_gap_s) + " s)";
      return res;
    }
    // World points of the match and its neighbours, the match's own first.
    std::unordered_map<std::uint64_t, Eigen::Vector3d> points;
    const std::vector<std::size_t>& nodes = seq_[std::size_t(m.sequence)].nodes;
    const auto pos = std::size_t(std::find(nodes.begin(), nodes.end(), index_.at(m.id)) - nodes.begin());
    for (int d = 0; d <= o_.neighbour_keyframes; ++d)
      for (const int sign : {-1, 1}) {
        if (d == 0 && sign > 0) continue;
        const std::ptrdiff_t k = std::ptrdiff_t(pos) + sign * d;
        if (k < 0 || k >= std::ptrdiff_t(nodes.size())) continue;
        for (const KeyframeFeature& f : kf_[nodes[std::size_t(k)]].record.features)
          if (f.has_point) points.emplace(f.id, f.p_w);
      }
    std::vector<Eigen::Vector3d> P;
    std::vector<Eigen::Vector2d> M;
    for (const KeyframeFeature& f : q.record.features) {
      const auto it = points.find(f.id);
      if (it == points.end() || !f.m.allFinite() || !it->second.allFinite()) continue;
      P.push_back(it->second);
      M.push_back(f.m);
    }
    res.correspondences = int(P.size());
    if (res.correspondences < o_.min_inliers) {
      res.status = LoopStatus::kTooFewCorrespondences;
      res.reason = std::to_string(res.correspondences) + " shared feature ids with a world point, fewer than " +
                   std::to_string(o_.min_inliers);
      return res;
    }
    // Within one group the graph already relates query and match: their
    // relative pose, put in the match's odometry frame, is RANSAC's first
    // hypothesis (as VINS-Mono starts its PnP from the odometry); it is
    // scored like any other and wins only on its inliers.
    std::optional<SE3d> guess;
    if (seq_[std::size_t(q.sequence)].group == seq_[std::size_t(m.sequence)].group)
      guess = m.record.T_w_b * (corrected_pose(m.id).inverse() * corrected_pose(q.id)) * q.record.T_b_c;
    const PnpResult pnp = solve_pnp_ransac(P, M, o_.pnp, guess);
    res.inliers = pnp.inliers;
    res.rms_residual = pnp.rms_residual;
    if (pnp.status != PnpStatus::kOk) {
      res.status = LoopStatus::kPnpFailed;
      res.reason = pnp.reason;
      return res;
    }
    const SE3d T_w_bq = pnp.T_w_c * q.record.T_b_c.inverse();  // query body in the match's odometry frame
    res.T_match_query = m.record.T_w_b.inverse() * T_w_bq;
    const Pose4Dof pm = pose_4dof(m.record.T_w_b), pq = pose_4dof(T_w_bq);
    Edge4Dof e;
    e.from = m.id;
    e.to = q.id;
    e.dp = res.T_match_query.translation();
    e.dyaw = wrap_angle(pq.yaw - pm.yaw);
    e.information = information(o_.loop_sigma_m, o_.loop_sigma_yaw_rad);
    e.loss = o_.loop_loss;
    res.edge = e;
    const double yaw_deg = std::abs(e.dyaw) * 180.0 / std::numbers::pi;
    if (yaw_deg > o_.max_relative_yaw_deg || e.dp.norm() > o_.max_relative_distance_m) {
      res.status = LoopStatus::kImplausible;
      res.reason = "relative pose " + fmt(e.dp.norm()) + " m, " + fmt(yaw_deg) + " deg is beyond " +
                   fmt(o_.max_relative_distance_m) + " m / " + fmt(o_.max_relative_yaw_deg) + " deg";
      return res;
    }
    res.status = LoopStatus::kAccepted;
    return res;
  }

  /// **Oracle** candidate from recurring feature ids: the keyframe of
  /// another sequence sharing the most feature ids with keyframe
  /// `query_id` (the earliest on a tie), when they share at least
  /// `min_shared` (then verify with add_loop_between(query_id, match_id)).
  /// Meaningful only when an id names one landmark for ever
  /// (simulated tracks with recurring ids, io/loop_candidates.hpp); used to
  /// find where a new session is in a loaded map. The candidate still goes
  /// through verification.
  /// @throws posefuse::invalid_argument for an unknown id
  [[nodiscard]] std::optional<SharedIdMatch> shared_id_match(std::int64_t query_id, int min_shared) const {
    const Keyframe& q = keyframe(query_id);
    std::unordered_map<std::size_t, int> count;
    for (const KeyframeFeature& f : q.record.features) {
      const auto it = keyframes_of_id_.find(f.id);
      if (it == keyframes_of_id_.end()) continue;
      for (const std::size_t k : it->second)
        if (kf_[k].sequence != q.sequence) ++count[k];
    }
    std::optional<SharedIdMatch> best;
    std::size_t best_k = 0;
    for (const auto& [k, n] : count)
      if (n >= min_shared && (!best || n > best->shared_ids || (n == best->shared_ids && k < best_k))) {
        best = SharedIdMatch{kf_[k].id, n};
        best_k = k;
      }
    return best;
  }

  /// The keyframe nearest to `t_ns` within the tolerance (any sequence; the
  /// newest sequence on a tie), or none.
  [[nodiscard]] std::optional<std::int64_t> keyframe_at(std::int64_t t_ns, int sequence = -1) const {
    std::optional<std::int64_t> best;
    double best_dt = std::numeric_limits<double>::infinity();
    for (int s = int(seq_.size()) - 1; s >= 0; --s) {
      if (sequence >= 0 && s != sequence) continue;
      const std::vector<std::size_t>& nodes = seq_[std::size_t(s)].nodes;
      const auto it = std::lower_bound(nodes.begin(), nodes.end(), t_ns,
                                       [&](std::size_t k, std::int64_t t) { return kf_[k].record.t_ns < t; });
      if (it != nodes.end()) consider(*it, t_ns, best, best_dt);  // the first at or after t_ns
      if (it != nodes.begin()) consider(*(it - 1), t_ns, best, best_dt);  // the last before
    }
    return best;
  }

  /// The live sequence's drift correction (identity before any loop).
  [[nodiscard]] DriftCorrection correction() const {
    return live_ < 0 ? DriftCorrection{} : seq_[std::size_t(live_)].correction;
  }
  /// The drift correction of sequence `s`.
  [[nodiscard]] const DriftCorrection& correction(int s) const { return seq_.at(std::size_t(s)).correction; }
  /// The live sequence (-1 before its first keyframe).
  [[nodiscard]] int live_sequence() const noexcept { return live_; }
  /// Number of sequences.
  [[nodiscard]] int sequences() const noexcept { return int(seq_.size()); }

  /// The keyframes in insertion order.
  [[nodiscard]] const std::vector<Keyframe>& keyframes() const noexcept { return kf_; }
  /// The keyframe with node id `id`.
  /// @throws posefuse::invalid_argument when there is none
  [[nodiscard]] const Keyframe& keyframe(std::int64_t id) const {
    const auto it = index_.find(id);
    if (it == index_.end()) throw invalid_argument("LoopClosure: no keyframe " + std::to_string(id));
    return kf_[it->second];
  }
  /// The corrected (graph) pose of keyframe `id` as a rigid pose: the graph's
  /// position and yaw with the odometry's roll and pitch.
  [[nodiscard]] SE3d corrected_pose(std::int64_t id) const {
    const Pose4Dof& x = graph_.pose(id);
    return SE3d(x.p, SO3d(Eigen::Matrix3d(rotation_from_euler_zyx(EulerZYX<double>{x.roll, x.pitch, x.yaw}))));
  }
  /// The pose graph (nodes are keyframe ids).
  [[nodiscard]] const PoseGraph4Dof& graph() const noexcept { return graph_; }
  /// Loop edges accepted so far.
  [[nodiscard]] int loops() const noexcept {
    return int(std::count(edge_kind_.begin(), edge_kind_.end(), MapEdgeKind::kLoop));
  }

  /// The database as a map (vio/vio_map.hpp): keyframes with their graph
  /// poses, edges of both kinds.
  [[nodiscard]] VioMap to_map() const {
    VioMap m;
    m.keyframes.reserve(kf_.size());
    for (const Keyframe& k : kf_) {
      MapKeyframe x;
      x.id = k.id;
      x.sequence = k.sequence;
      x.t_ns = k.record.t_ns;
      x.T_w_b = MapPose::of(k.record.T_w_b);
      x.T_b_c = MapPose::of(k.record.T_b_c);
      x.pose = graph_.pose(k.id);
      x.fixed = graph_.is_fixed(k.id);
      x.features = k.record.features;
      m.keyframes.push_back(std::move(x));
    }
    for (std::size_t e = 0; e < graph_.edges().size(); ++e) m.edges.push_back(MapEdge{edge_kind_[e], graph_.edges()[e]});
    return m;
  }

  /// Adds a map: its keyframes (new node ids, their sequences renumbered
  /// after the existing ones, poses as stored), its edges, and which nodes
  /// it fixes. With `fixed`, every node of the map is held fixed (a map to
  /// localise in, which loops must not bend). The map's sequences form one
  /// group, anchored at its fixed nodes, apart from the existing ones until
  /// a loop joins them. The live sequence ends (the next keyframe starts a
  /// new one). Returns the node id given to the map's first keyframe (ids
  /// are given in the map's order).
  /// @throws posefuse::invalid_argument when an edge names a keyframe the map lacks
  std::int64_t add_map(const VioMap& map, bool fixed = false) {
    if (map.keyframes.empty()) throw invalid_argument("LoopClosure::add_map: the map has no keyframe");
    live_ = -1;
    const std::int64_t first = next_id_;
    std::unordered_map<std::int64_t, std::int64_t> id_of;
    std::unordered_map<int, int> seq_of;
    int group = -1;
    bool any_fixed = false;
    for (const MapKeyframe& k : map.keyframes) {
      auto [it, fresh] = seq_of.emplace(k.sequence, 0);
      if (fresh) {
        it->second = new_sequence();
        if (group < 0) group = it->second;
        seq_[std::size_t(it->second)].group = group;
      }
      const std::int64_t id = next_id_++;
      if (!id_of.emplace(k.id, id).second)
        throw invalid_argument("LoopClosure::add_map: keyframe id " + std::to_string(k.id) + " twice");
      Keyframe x{id, it->second, KeyframeRecord{k.t_ns, k.T_w_b.se3(), k.T_b_c.se3(), k.features}};
      add_node(std::move(x), k.pose, fixed || k.fixed);
      if (!fixed && k.fixed) anchors_.insert(id);  // the map's own gauge: released when it joins another group
      any_fixed = any_fixed || fixed || k.fixed;
    }
    if (!any_fixed) {
      graph_.set_fixed(first, true);
      anchors_.insert(first);
    }
    for (const MapEdge& e : map.edges) {
      const auto a = id_of.find(e.edge.from), b = id_of.find(e.edge.to);
      if (a == id_of.end() || b == id_of.end())
        throw invalid_argument("LoopClosure::add_map: an edge names a keyframe the map does not have");
      Edge4Dof x = e.edge;
      x.from = a->second;
      x.to = b->second;
      graph_.add_edge(x);
      edge_kind_.push_back(e.kind);
    }
    // Per sequence: the correction of its newest keyframe (for keyframes added to it later).
    for (const auto& [old, s] : seq_of) update_correction(s);
    return first;
  }

 private:
  struct Sequence {
    std::vector<std::size_t> nodes;  // indices into kf_, in time order
    int group = 0;                   // the first sequence of its group
    DriftCorrection correction;
  };

  static std::string fmt(double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", x);
    return b;
  }

  static Eigen::Matrix4d information(double sigma_m, double sigma_yaw) {
    return Eigen::Vector4d(1 / (sigma_m * sigma_m), 1 / (sigma_m * sigma_m), 1 / (sigma_m * sigma_m),
                           1 / (sigma_yaw * sigma_yaw))
        .asDiagonal();
  }

  Edge4Dof sequential_edge(std::int64_t from, const SE3d& T_a, std::int64_t to, const SE3d& T_b) const {
    const Pose4Dof a = pose_4dof(T_a), b = pose_4dof(T_b);
    Edge4Dof e;
    e.from = from;
    e.to = to;
    e.dp = T_a.so3().matrix().transpose() * (T_b.translation() - T_a.translation());
    e.dyaw = wrap_angle(b.yaw - a.yaw);
    e.information = information(o_.sequential_sigma_m, o_.sequential_sigma_yaw_rad);
    return e;
  }

  int new_sequence() {
    Sequence s;
    s.group = int(seq_.size());
    seq_.push_back(s);
    return int(seq_.size()) - 1;
  }

  void add_node(Keyframe k, const Pose4Dof& pose, bool fixed) {
    graph_.add_node(k.id, pose, fixed);
    index_.emplace(k.id, kf_.size());
    for (const KeyframeFeature& f : k.record.features) keyframes_of_id_[f.id].push_back(kf_.size());
    seq_[std::size_t(k.sequence)].nodes.push_back(kf_.size());
    kf_.push_back(std::move(k));
  }

  void consider(std::size_t k, std::int64_t t_ns, std::optional<std::int64_t>& best, double& best_dt) const {
    const double dt = std::abs(double(kf_[k].record.t_ns - t_ns)) * 1e-9;
    if (dt <= o_.stamp_tolerance_s && dt < best_dt) {
      best_dt = dt;
      best = kf_[k].id;
    }
  }

  // The query: the newest sequence with a keyframe within the tolerance.
  [[nodiscard]] std::optional<std::int64_t> query_keyframe(std::int64_t t_ns) const {
    for (int s = int(seq_.size()) - 1; s >= 0; --s)
      if (const std::optional<std::int64_t> k = keyframe_at(t_ns, s)) return k;
    return std::nullopt;
  }

  void update_correction(int s) {
    Sequence& q = seq_[std::size_t(s)];
    if (q.nodes.empty()) return;
    const Keyframe& k = kf_[q.nodes.back()];
    q.correction = DriftCorrection::between(pose_4dof(k.record.T_w_b), graph_.pose(k.id));
  }

  // True when a node of group g is held fixed for good (a map added with fixed = true).
  [[nodiscard]] bool pinned(int g) const {
    for (std::size_t s = 0; s < seq_.size(); ++s)
      if (seq_[s].group == g)
        for (const std::size_t k : seq_[s].nodes)
          if (graph_.is_fixed(kf_[k].id) && !anchors_.count(kf_[k].id)) return true;
    return false;
  }

  void accept(LoopResult& res) {
    const Keyframe& q = keyframe(res.query_id);
    const Keyframe& m = keyframe(res.match_id);
    const int gq = seq_[std::size_t(q.sequence)].group, gm = seq_[std::size_t(m.sequence)].group;
    if (gq != gm) {
      // Move one group (the query's, unless only it is pinned) so that the
      // loop holds exactly, release its anchors, and join the groups.
      const bool move_query = !pinned(gq) || pinned(gm);
      const Pose4Dof& xm = graph_.pose(m.id);
      const Pose4Dof& xq = graph_.pose(q.id);
      DriftCorrection move;
      if (move_query) {
        Pose4Dof target = xq;
        target.p = xm.p + rotation_from_euler_zyx(EulerZYX<double>{xm.roll, xm.pitch, xm.yaw}) * res.edge.dp;
        target.yaw = wrap_angle(xm.yaw + res.edge.dyaw);
        move = DriftCorrection::between(xq, target);
      } else {
        Pose4Dof target = xm;
        target.yaw = wrap_angle(xq.yaw - res.edge.dyaw);
        target.p = xq.p - rotation_from_euler_zyx(EulerZYX<double>{xm.roll, xm.pitch, target.yaw}) * res.edge.dp;
        move = DriftCorrection::between(xm, target);
      }
      const int moved = move_query ? gq : gm, kept = move_query ? gm : gq;
      for (std::size_t s = 0; s < seq_.size(); ++s) {
        if (seq_[s].group != moved) continue;
        for (const std::size_t k : seq_[s].nodes) {
          const std::int64_t id = kf_[k].id;
          graph_.set_pose(id, move.apply(graph_.pose(id)));
          if (anchors_.erase(id) > 0) graph_.set_fixed(id, false);
        }
        seq_[s].group = kept;
      }
      res.merged = true;
    }
    graph_.add_edge(res.edge);
    edge_kind_.push_back(MapEdgeKind::kLoop);
    res.summary = graph_.optimize(o_.graph);
    for (int s = 0; s < int(seq_.size()); ++s) update_correction(s);
    res.after = correction();
  }

  LoopClosureOptions o_;
  PoseGraph4Dof graph_;
  std::vector<MapEdgeKind> edge_kind_;  // one per graph edge
  std::vector<Keyframe> kf_;
  std::unordered_map<std::int64_t, std::size_t> index_;  // node id -> kf_ index
  std::vector<Sequence> seq_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> keyframes_of_id_;  // feature id -> kf_ indices
  std::unordered_set<std::int64_t> anchors_;  // fixed nodes that only fix their group's gauge
  int live_ = -1;
  std::int64_t next_id_ = 0;
};

}  // namespace posefuse
