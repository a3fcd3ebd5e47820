#include "engine/dense_checks.hpp"

#include "core/errors.hpp"

#include <algorithm>
#include <cmath>

namespace kushner {

void check_dense_shape(const std::string& name, const Eigen::MatrixXd& m, long rows, long cols) {
  const bool rows_ok = rows < 0 || m.rows() == rows, cols_ok = cols < 0 || m.cols() == cols;
  KUSHNER_INPUT_REQUIRE(rows_ok && cols_ok, name << ": is " << m.rows() << "x" << m.cols() << ", expected "
                                                 << (rows < 0 ? std::string("any") : std::to_string(rows)) << "x"
                                                 << (cols < 0 ? std::string("any") : std::to_string(cols)));
  KUSHNER_INPUT_REQUIRE(m.allFinite(), name << ": not finite");
}

void check_dense_positive_definite(const std::string& name, const Eigen::MatrixXd& m) {
  check_dense_shape(name, m, m.rows(), m.rows());
  const double scale = m.size() == 0 ? 1.0 : std::max(1.0, m.cwiseAbs().maxCoeff());
  KUSHNER_INPUT_REQUIRE((m - m.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * scale, name << ": not symmetric");
  Eigen::MatrixXd work = m;
  const long n = m.rows();
  for (long j = 0; j < n; ++j) {  // plain Cholesky, to name the pivot that fails
    double d = work(j, j);
    for (long k = 0; k < j; ++k) d -= work(j, k) * work(j, k);
    KUSHNER_INPUT_REQUIRE(d > 0.0, name << ": not positive definite (pivot " << j + 1 << ")");
    work(j, j) = std::sqrt(d);
    for (long i = j + 1; i < n; ++i) {
      double s = work(i, j);
      for (long k = 0; k < j; ++k) s -= work(i, k) * work(j, k);
      work(i, j) = s / work(j, j);
    }
  }
}

}  // namespace kushner
