#pragma once
// Basic algebra types. Units are those of docs/units.md: d = 1, P = 1, eta = 1.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace sheardiff {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;  // (u_x, u_y, omega_z) of one particle
using Mat2 = Eigen::Matrix2d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using VecX = Eigen::VectorXd;
// Three dimensions: a vector of space (a position, a velocity, an angular velocity), a 3x3
// operator on it, and the 12x12 block of a pair of spheres in the order (u, omega)_i,
// (u, omega)_j.
using Space3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Vec12 = Eigen::Matrix<double, 12, 1>;

inline constexpr double kPi = 3.14159265358979323846;

// 2D cross product z-component and the in-plane perpendicular t = z x n.
inline double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}
inline Vec2 perp(const Vec2& n) {
  return {-n.y(), n.x()};
}
// The matrix of n x . : cross_matrix(n) v = n x v.
inline Mat3 cross_matrix(const Space3& n) {
  Mat3 m;
  m << 0.0, -n.z(), n.y(), n.z(), 0.0, -n.x(), -n.y(), n.x(), 0.0;
  return m;
}

}  // namespace sheardiff
