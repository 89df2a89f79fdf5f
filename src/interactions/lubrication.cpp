#include "sheardiff/interactions/lubrication.hpp"

#include <algorithm>
#include <cmath>

namespace sheardiff {

PairResistance Lubrication::coefficients(double ai, double aj, double h) const {
  const double he = std::max(h, 0.0) + delta;
  const double ln = 1.0 / he;
  // The log modes are cut where ln(1/(h+delta)) would turn negative.
  const double lt = tangential && ln > 1.0 ? std::log(ln) : 0.0;
  const double s = ai + aj;
  const double s2 = s * s, s3 = s2 * s;
  const double c = 6.0 * kPi;
  PairResistance p;
  p.xa = c * 2.0 * ai * ai * aj * aj / s3 * ln;
  p.ya = c * (4.0 / 15.0) * ai * aj * (2.0 * ai * ai + ai * aj + 2.0 * aj * aj) / s3 * lt;
  p.beta_i = c * (2.0 / 15.0) * ai * ai * aj * (4.0 * ai + aj) / s2 * lt;
  p.beta_j = c * (2.0 / 15.0) * ai * aj * aj * (ai + 4.0 * aj) / s2 * lt;
  p.gam_ii = c * (8.0 / 15.0) * ai * ai * ai * aj / s * lt;
  p.gam_jj = c * (8.0 / 15.0) * ai * aj * aj * aj / s * lt;
  p.gam_ij = c * (2.0 / 15.0) * ai * ai * aj * aj / s * lt;
  return p;
}

Mat6 PairResistance::matrix(const Vec2& n, const Vec2& t) const {
  const Mat2 a = xa * n * n.transpose() + ya * t * t.transpose();
  Mat6 m;
  m.block<2, 2>(0, 0) = a;
  m.block<2, 2>(0, 3) = -a;
  m.block<2, 2>(3, 0) = -a;
  m.block<2, 2>(3, 3) = a;
  m.block<2, 1>(0, 2) = beta_i * t;
  m.block<2, 1>(0, 5) = beta_j * t;
  m.block<2, 1>(3, 2) = -beta_i * t;
  m.block<2, 1>(3, 5) = -beta_j * t;
  m.block<1, 2>(2, 0) = beta_i * t.transpose();
  m.block<1, 2>(2, 3) = -beta_i * t.transpose();
  m.block<1, 2>(5, 0) = beta_j * t.transpose();
  m.block<1, 2>(5, 3) = -beta_j * t.transpose();
  m(2, 2) = gam_ii;
  m(2, 5) = gam_ij;
  m(5, 2) = gam_ij;
  m(5, 5) = gam_jj;
  return m;
}

Mat12 PairResistance::matrix_3d(const Space3& n) const {
  const Mat3 nn = n * n.transpose();
  const Mat3 plane = Mat3::Identity() - nn;  // onto the plane normal to n
  const Mat3 a = xa * nn + ya * plane;
  // The torque on i is -beta_i n x (u_i - u_j), the force on i from the spins
  // beta_i omega_i x n = -beta_i (n x omega_i): in 2D, beta_i omega_i t with t = z x n.
  const Mat3 nx = cross_matrix(n);
  Mat12 m;
  m.block<3, 3>(0, 0) = a;
  m.block<3, 3>(0, 3) = -beta_i * nx;
  m.block<3, 3>(0, 6) = -a;
  m.block<3, 3>(0, 9) = -beta_j * nx;
  m.block<3, 3>(3, 0) = beta_i * nx;
  m.block<3, 3>(3, 3) = gam_ii * plane;
  m.block<3, 3>(3, 6) = -beta_i * nx;
  m.block<3, 3>(3, 9) = gam_ij * plane;
  m.block<3, 3>(6, 0) = -a;
  m.block<3, 3>(6, 3) = beta_i * nx;
  m.block<3, 3>(6, 6) = a;
  m.block<3, 3>(6, 9) = beta_j * nx;
  m.block<3, 3>(9, 0) = beta_j * nx;
  m.block<3, 3>(9, 3) = gam_ij * plane;
  m.block<3, 3>(9, 6) = -beta_j * nx;
  m.block<3, 3>(9, 9) = gam_jj * plane;
  return m;
}

}  // namespace sheardiff
