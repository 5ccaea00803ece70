#pragma once
/// @file
/// Loop candidates: pairs of image stamps that a place-recognition front end
/// believes show the same place, as a csv, and an **oracle** that derives
/// them from feature ids that recur in a FeatureTracks.
///
///     t_ns_query,t_ns_match
///     1403715400012143104,1403715290062143232
///
/// * `t_ns_query`: the stamp of the newer image (ns, int64);
/// * `t_ns_match`: the stamp of the older image it is believed to match
///   (ns, int64), strictly earlier than the query.
///
/// **Strictness.** Blank lines and lines starting with '#' are skipped; the
/// first other line may be the header `t_ns_query,t_ns_match`. Every other
/// line has exactly 2 comma-separated integer fields (spaces around them
/// allowed), or it is a posefuse::io_error `file:line: reason`; so is a
/// match that is not earlier than its query. Rows need not be sorted; the
/// reader returns them sorted by query stamp (then match stamp), duplicates
/// kept. A file without rows is an empty list, not an error (no loop found).
///
/// Whether a candidate is a true loop is for the verifier to decide
/// (vio/loop_closure.hpp); the file only proposes.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/csv.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/euroc.hpp>
#include <posefuse/io/feature_tracks.hpp>

namespace posefuse {

/// A loop candidate: the image at `t_query_ns` may show the place seen at `t_match_ns`.
struct LoopCandidate {
  std::int64_t t_query_ns = 0;  ///< the newer image (ns)
  std::int64_t t_match_ns = 0;  ///< the older image (ns), < t_query_ns
  /// Number of shared feature ids (the oracle's count; 0 when read from a file).
  int shared_ids = 0;
};

/// The header line the writer writes and the reader accepts.
inline constexpr std::string_view kLoopCandidateHeader = "t_ns_query,t_ns_match";

/// Reads a loop-candidate csv (see the file comment).
/// @return the candidates sorted by (t_query_ns, t_match_ns)
/// @throws posefuse::io_error (file:line) for a malformed row or a match
///         not earlier than its query; (file) when it cannot be read
template <class Lazy = void>
[[nodiscard]] std::vector<LoopCandidate> read_loop_candidates(const std::filesystem::path& file) {
  detail::LineReader reader(file);
  std::vector<LoopCandidate> out;
  std::string line;
  bool first = true;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    const std::vector<std::string_view> f = detail::split_csv(line);
    if (first) {
      first = false;
      if (f.size() == 2 && f[0] == "t_ns_query" && f[1] == "t_ns_match") continue;
    }
    if (f.size() != 2)
      throw io_error(file, n,
                     "expected 2 comma-separated fields (t_ns_query, t_ns_match), found " + std::to_string(f.size()));
    LoopCandidate c;
    c.t_query_ns = detail::parse_stamp(f[0], file, n);
    try {
      c.t_match_ns = detail::parse_stamp(f[1], file, n);
    } catch (const io_error&) {
      throw io_error(file, n, "cannot parse '" + std::string(f[1]) +
                                  "' in column 2 as an integer timestamp in nanoseconds");
    }
    if (!(c.t_match_ns < c.t_query_ns))
      throw io_error(file, n,
                     "the match " + std::to_string(c.t_match_ns) + " ns is not earlier than the query " +
                         std::to_string(c.t_query_ns) + " ns");
    out.push_back(c);
  }
  std::stable_sort(out.begin(), out.end(), [](const LoopCandidate& a, const LoopCandidate& b) {
    return a.t_query_ns != b.t_query_ns ? a.t_query_ns < b.t_query_ns : a.t_match_ns < b.t_match_ns;
  });
  return out;
}

/// Writes loop candidates as csv with the header line.
/// @throws posefuse::invalid_argument for a match not earlier than its query (nothing is written)
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_loop_candidates(const std::filesystem::path& file, const std::vector<LoopCandidate>& c) {
  for (std::size_t k = 0; k < c.size(); ++k)
    if (!(c[k].t_match_ns < c[k].t_query_ns))
      throw invalid_argument("write_loop_candidates: candidate " + std::to_string(k) +
                             ": the match is not earlier than the query");
  std::ofstream out = detail::traj_io::open_output(file);
  out << kLoopCandidateHeader << '\n';
  for (const LoopCandidate& x : c) out << x.t_query_ns << ',' << x.t_match_ns << '\n';
  detail::traj_io::finish_output(out, file);
}

/// Options of loop_candidates_from_recurring_ids.
struct RecurringIdOptions {
  double min_gap_s = 20.0;          ///< the match is at least this much older than the query (s)
  int min_shared_ids = 30;          ///< fewer shared ids: no candidate for that query
  double min_query_spacing_s = 1.0;  ///< queries of successive candidates at least this far apart (s)
};

/// **Oracle** loop candidates from feature ids that recur: for each frame
/// (query, in time order), the earlier frame at least `min_gap_s` older
/// that shares the most feature ids with it (the earliest such frame on a
/// tie), kept when they share at least `min_shared_ids`; a query at least
/// `min_query_spacing_s` after the previous kept one.
///
/// This is only meaningful when an id names one landmark for ever, i.e.
/// when the same physical point seen again gets the same id. A real
/// front end gives a re-detected point a new id, so on real tracks this
/// finds nothing; the feature-track simulator keeps ids of recurring
/// landmarks when asked to (sim/feature_tracks.hpp, `recurring_ids`), and
/// then these candidates are the ground truth's place recognition: an
/// oracle, not a place recogniser. The candidates still go through the
/// geometric verification (vio/loop_closure.hpp) like any other.
/// @throws posefuse::invalid_argument for negative options
template <class Lazy = void>
[[nodiscard]] std::vector<LoopCandidate> loop_candidates_from_recurring_ids(const FeatureTracks& tracks,
                                                                            const RecurringIdOptions& o = {}) {
  if (!(o.min_gap_s >= 0) || o.min_shared_ids < 1 || !(o.min_query_spacing_s >= 0))
    throw invalid_argument("loop_candidates_from_recurring_ids: min_gap_s and min_query_spacing_s must be >= 0, "
                           "min_shared_ids >= 1");
  const auto gap_ns = std::int64_t(o.min_gap_s * 1e9), spacing_ns = std::int64_t(o.min_query_spacing_s * 1e9);
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> frames_of;  // id -> frames seeing it, in order
  std::vector<int> count(tracks.size(), 0);
  std::vector<std::size_t> touched;
  std::vector<LoopCandidate> out;
  std::size_t oldest = 0;  // frames [0, oldest) are at least min_gap older than the current query
  for (std::size_t q = 0; q < tracks.size(); ++q) {
    const std::int64_t tq = tracks[q].t_ns;
    while (oldest < q && tracks[oldest].t_ns <= tq - gap_ns) ++oldest;
    const bool spaced = out.empty() || tq - out.back().t_query_ns >= spacing_ns;
    if (spaced && oldest > 0) {
      touched.clear();
      for (const FeatureObservation& f : tracks[q].features) {
        const auto it = frames_of.find(f.id);
        if (it == frames_of.end()) continue;
        for (const std::size_t m : it->second) {
          if (m >= oldest) break;
          if (count[m]++ == 0) touched.push_back(m);
        }
      }
      std::size_t best = 0;
      int best_n = 0;
      for (const std::size_t m : touched) {
        if (count[m] > best_n || (count[m] == best_n && m < best)) {
          best_n = count[m];
          best = m;
        }
        count[m] = 0;
      }
      if (best_n >= o.min_shared_ids) out.push_back(LoopCandidate{tq, tracks[best].t_ns, best_n});
    }
    for (const FeatureObservation& f : tracks[q].features) frames_of[f.id].push_back(q);
  }
  return out;
}

}  // namespace posefuse
