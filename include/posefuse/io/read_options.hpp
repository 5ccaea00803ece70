#pragma once
/// @file
/// Tolerances the trajectory readers apply to the rotations they read.

namespace posefuse {

/// How strictly the KITTI and TUM readers check rotations.
///
/// Real files are written with 6 to 9 significant digits and some come from
/// odometry that composes poses in single precision, so their rotations are
/// only nearly orthonormal. On KITTI 06, the largest
/// \f$ \max_{ij} |(R^\top R - I)_{ij}| \f$ is 1.7e-7 (ground truth), 5.0e-7
/// (ORB-SLAM2 stereo) and 4.1e-4 (CVO odometry). Accepted rotations are
/// re-orthonormalised (nearest rotation in the Frobenius norm), accepted
/// quaternions are normalised.
struct ReadOptions {
  /// Largest accepted \f$ \max_{ij} |(R^\top R - I)_{ij}| \f$ of a KITTI rotation.
  double rotation_tolerance = 1e-3;
  /// Largest accepted \f$ |\lVert q \rVert - 1| \f$ of a TUM quaternion.
  double quaternion_norm_tolerance = 1e-3;
};

}  // namespace posefuse
