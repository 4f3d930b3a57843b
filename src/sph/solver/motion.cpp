#include <sph/solver/motion.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <sph/core/error.h>

namespace sph {

namespace {

/// R for `angle` radians about the unit `axis` (Rodrigues' formula; 2D: about z).
template <int D>
std::array<double, 9> rotation_matrix(const Vec<3, double>& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  if constexpr (D == 2) return {c, -s, 0, s, c, 0, 0, 0, 1};
  const double x = axis[0], y = axis[1], z = axis[2], k = 1 - c;
  return {c + x * x * k,     x * y * k - z * s, x * z * k + y * s,  //
          y * x * k + z * s, c + y * y * k,     y * z * k - x * s,  //
          z * x * k - y * s, z * y * k + x * s, c + z * z * k};
}

/// The angular velocity vector of `rate` rad/s about `axis` (2D: about z).
template <int D>
Vec<3, double> spin(const Vec<3, double>& axis, double rate) {
  if constexpr (D == 2) return {{0, 0, rate}};
  return axis * rate;
}

}  // namespace

template <int D>
RigidPose<D> pose_at(const ObstacleMotion<D>& m, double t) {
  RigidPose<D> p;
  p.center = m.center;
  // The ramp r(t) = min(t / ramp, 1) and its derivative.
  const bool ramping = m.ramp_time > 0 && t < m.ramp_time;
  const double r = ramping ? std::max(t, 0.0) / m.ramp_time : 1.0;
  const double dr = ramping && t >= 0 ? 1.0 / m.ramp_time : 0.0;
  switch (m.type) {
    case MotionType::None:
      break;
    case MotionType::Oscillation: {
      SPH_CHECK(m.period > 0, "an oscillation needs a positive period");
      // (minus sin(phase): at t = 0 the obstacle is where the scene puts it, whatever the phase)
      const double w = 2 * std::numbers::pi / m.period, arg = w * t + m.phase, s0 = std::sin(m.phase);
      p.translation = m.direction * (m.amplitude * r * (std::sin(arg) - s0));
      p.velocity = m.direction * (m.amplitude * (dr * (std::sin(arg) - s0) + r * w * std::cos(arg)));
      break;
    }
    case MotionType::Rotation: {
      // The angular velocity ramps up linearly: the angle is w t^2 / (2 ramp) during the ramp.
      const double tt = std::max(t, 0.0);
      const double angle = ramping ? m.angular_velocity * tt * tt / (2 * m.ramp_time)
                                   : m.angular_velocity * (tt - 0.5 * std::min(m.ramp_time, tt));
      p.rotation = rotation_matrix<D>(m.axis, angle);
      p.angular_velocity = spin<D>(m.axis, m.angular_velocity * r);
      break;
    }
    case MotionType::Keyframes: {
      SPH_CHECK(!m.keys.empty(), "keyframes need at least one key");
      const auto& k = m.keys;
      if (t < k.front().time || k.size() == 1) {  // (the first key's own time starts its segment)
        p.translation = k.front().translation;
        p.rotation = rotation_matrix<D>(m.axis, k.front().rotation);
        break;
      }
      if (t >= k.back().time) {
        p.translation = k.back().translation;
        p.rotation = rotation_matrix<D>(m.axis, k.back().rotation);
        break;
      }
      // The segment [k[s], k[s + 1]) holding t (a key's own time starts its segment).
      const auto next =
          std::upper_bound(k.begin(), k.end(), t, [](double v, const MotionKey<D>& key) { return v < key.time; });
      const MotionKey<D>& a = *(next - 1);
      const MotionKey<D>& b = *next;
      const double span = b.time - a.time, f = (t - a.time) / span;
      p.translation = a.translation + (b.translation - a.translation) * f;
      p.velocity = (b.translation - a.translation) * (1.0 / span);
      p.rotation = rotation_matrix<D>(m.axis, a.rotation + (b.rotation - a.rotation) * f);
      p.angular_velocity = spin<D>(m.axis, (b.rotation - a.rotation) / span);
      break;
    }
  }
  return p;
}

template <int D>
double max_surface_speed(const ObstacleMotion<D>& m, const Vec<D, double>& lo, const Vec<D, double>& hi, double t) {
  if (!m.moves()) return 0;
  return pose_surface_speed<D>(pose_at(m, t), lo, hi);
}

template RigidPose<2> pose_at<2>(const ObstacleMotion<2>&, double);
template RigidPose<3> pose_at<3>(const ObstacleMotion<3>&, double);
template double max_surface_speed<2>(const ObstacleMotion<2>&, const Vec<2, double>&, const Vec<2, double>&, double);
template double max_surface_speed<3>(const ObstacleMotion<3>&, const Vec<3, double>&, const Vec<3, double>&, double);

}  // namespace sph
