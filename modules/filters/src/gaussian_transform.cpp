// A rigid motion of Gaussians. The SH rotation of each band is solved, not tabulated: the band's
// basis sampled at fixed directions d_s and at R^T d_s gives Y(d) M = Y(R^T d), solved in the
// least-squares sense (exact: a band is closed under rotation, and 64 directions span it).
#include "sadsplat/filters/gaussian_transform.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace filters {
namespace {

constexpr int kSampleDirections = 64;

// The real SH basis of degrees 1..3 at the unit direction d, with the constants and signs of
// 3DGS (and of KHR_gaussian_splatting's appendix): 15 values, degree 1 first.
Eigen::Matrix<double, 15, 1> shRestBasis(const Eigen::Vector3d& d) {
  const double x = d.x(), y = d.y(), z = d.z();
  const double xx = x * x, yy = y * y, zz = z * z;
  Eigen::Matrix<double, 15, 1> b;
  const double c1 = 0.4886025119029199;
  b << -c1 * y, c1 * z, -c1 * x,  //
      1.0925484305920792 * x * y, -1.0925484305920792 * y * z,
      0.31539156525252005 * (2 * zz - xx - yy), -1.0925484305920792 * x * z,
      0.5462742152960396 * (xx - yy),  //
      -0.5900435899266435 * y * (3 * xx - yy), 2.890611442640554 * x * y * z,
      -0.4570457994644658 * y * (4 * zz - xx - yy),
      0.3731763325901154 * z * (2 * zz - 3 * xx - 3 * yy),
      -0.4570457994644658 * x * (4 * zz - xx - yy), 1.445305721320277 * z * (xx - yy),
      -0.5900435899266435 * x * (xx - 3 * yy);
  return b;
}

// Fixed, well-spread unit directions (a Fibonacci sphere).
Eigen::Vector3d sampleDirection(int i) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (2.0 * i + 1.0) / kSampleDirections;
  const double r = std::sqrt(1.0 - z * z);
  return {r * std::cos(golden * i), r * std::sin(golden * i), z};
}

void checkRotation(const Eigen::Matrix3d& r) {
  const double orthogonality = (r * r.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (!(orthogonality < 1e-6) || !(std::abs(r.determinant() - 1.0) < 1e-6)) {
    std::ostringstream got;
    got << "|R R^T - I| = " << orthogonality << ", det " << r.determinant();
    throw Error("<transformGaussians>", "rotation", "a rotation matrix (orthonormal, det +1)",
                got.str());
  }
}

}  // namespace

std::array<Eigen::MatrixXd, 3> shRotationMatrices(const Eigen::Matrix3d& rotation) {
  checkRotation(rotation);
  Eigen::MatrixXd at_d(kSampleDirections, 15), at_rotated(kSampleDirections, 15);
  for (int s = 0; s < kSampleDirections; ++s) {
    const Eigen::Vector3d d = sampleDirection(s);
    at_d.row(s) = shRestBasis(d).transpose();
    at_rotated.row(s) = shRestBasis(rotation.transpose() * d).transpose();
  }
  std::array<Eigen::MatrixXd, 3> m;
  int first = 0;
  for (int l = 1; l <= 3; ++l) {
    const int n = 2 * l + 1;
    // Solve Y_l(d) X = Y_l(R^T d), i.e. Y_j(R^T d) = sum_k X_kj Y_k(d); then
    // sum_j c_j Y_j(R^T d) = sum_k (X c)_k Y_k(d): M = X.
    m[l - 1] = at_d.middleCols(first, n)
                   .colPivHouseholderQr()
                   .solve(at_rotated.middleCols(first, n));
    first += n;
  }
  return m;
}

void transformGaussians(const pcl::PointCloud<GaussianPoint>& in,
                        pcl::PointCloud<GaussianPoint>& out, const Eigen::Matrix3d& rotation,
                        const Eigen::Vector3d& translation) {
  const std::array<Eigen::MatrixXd, 3> sh = shRotationMatrices(rotation);
  const Eigen::Quaterniond qr(rotation);
  if (&out != &in) out = in;
  for (GaussianPoint& p : out.points) {
    const Eigen::Vector3d x = rotation * Eigen::Vector3d(p.x, p.y, p.z) + translation;
    p.x = static_cast<float>(x.x());
    p.y = static_cast<float>(x.y());
    p.z = static_cast<float>(x.z());
    // The Gaussian's own frame to the world is q; to the moved world, q_R q.
    const Eigen::Quaterniond q(p.rot[0], p.rot[1], p.rot[2], p.rot[3]);
    const Eigen::Quaterniond moved = qr * q;
    p.rot[0] = static_cast<float>(moved.w());
    p.rot[1] = static_cast<float>(moved.x());
    p.rot[2] = static_cast<float>(moved.y());
    p.rot[3] = static_cast<float>(moved.z());
    const Eigen::Vector3d n = rotation * Eigen::Vector3d(p.nx, p.ny, p.nz);
    p.nx = static_cast<float>(n.x());
    p.ny = static_cast<float>(n.y());
    p.nz = static_cast<float>(n.z());
    for (int c = 0; c < 3; ++c) {
      float* coefficients = p.f_rest + c * kShRestPerChannel;
      int first = 0;
      for (int l = 1; l <= 3; ++l) {
        const int n_l = 2 * l + 1;
        Eigen::VectorXd v(n_l);
        for (int k = 0; k < n_l; ++k) v[k] = coefficients[first + k];
        const Eigen::VectorXd rotated = sh[l - 1] * v;
        for (int k = 0; k < n_l; ++k) coefficients[first + k] = static_cast<float>(rotated[k]);
        first += n_l;
      }
    }
  }
}

}  // namespace filters
}  // namespace sadsplat
