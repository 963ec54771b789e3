#include "miner/core/error.hpp"

#include <cmath>
#include <sstream>

namespace miner {

std::string format_point(const Eigen::Vector3d& p) {
  std::ostringstream os;
  os.precision(10);
  os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return os.str();
}

void require_finite(double v, const std::string& field) {
  if (!std::isfinite(v)) {
    std::ostringstream os;
    os << field << ": must be a finite number, got " << v;
    throw Error(os.str());
  }
}

void require_finite(const Eigen::Vector3d& v, const std::string& field) {
  for (int i = 0; i < 3; ++i) require_finite(v[i], field + "[" + std::to_string(i) + "]");
}

}  // namespace miner
