#include <sph/solver/rigid_body.h>

#include <cmath>
#include <limits>
#include <numbers>

#include <sph/core/error.h>

namespace sph {

namespace {

/// R v and R^T v for a row-major 3 x 3 R.
Vec<3, double> times(const std::array<double, 9>& r, const Vec<3, double>& v) {
  return {{r[0] * v[0] + r[1] * v[1] + r[2] * v[2], r[3] * v[0] + r[4] * v[1] + r[5] * v[2],
           r[6] * v[0] + r[7] * v[1] + r[8] * v[2]}};
}
Vec<3, double> times_transposed(const std::array<double, 9>& r, const Vec<3, double>& v) {
  return {{r[0] * v[0] + r[3] * v[1] + r[6] * v[2], r[1] * v[0] + r[4] * v[1] + r[7] * v[2],
           r[2] * v[0] + r[5] * v[1] + r[8] * v[2]}};
}

Vec<3, double> cross(const Vec<3, double>& a, const Vec<3, double>& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}

}  // namespace

std::array<double, 9> quaternion_matrix(const std::array<double, 4>& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

double body_contact_rate(double max_dt) {
  SPH_CHECK(max_dt > 0, "body_contact_rate: a positive step");
  return std::numbers::pi / (10 * max_dt);
}

template <int D>
MassProperties<D> box_mass_properties(const Box<D>& box, double density) {
  MassProperties<D> mp;
  const Vec<D, double> size = box.hi - box.lo;
  double volume = 1;
  for (int d = 0; d < D; ++d) volume *= size[d];
  mp.mass = density * volume;
  mp.center = (box.lo + box.hi) * 0.5;
  if constexpr (D == 2) {
    const double iz = mp.mass * (size[0] * size[0] + size[1] * size[1]) / 12;
    mp.inertia = {{iz, iz, iz}};  // (a 2D body turns about z only: the others never act)
  } else {
    const double a2 = size[0] * size[0], b2 = size[1] * size[1], c2 = size[2] * size[2];
    mp.inertia = {{mp.mass * (b2 + c2) / 12, mp.mass * (a2 + c2) / 12, mp.mass * (a2 + b2) / 12}};
  }
  return mp;
}

template <int D>
RigidBodyState<D> initial_body_state(const Box<D>& box, const BodyParams<D>& params) {
  RigidBodyState<D> s;
  s.position = (box.lo + box.hi) * 0.5;
  s.velocity = params.velocity;
  s.angular_velocity = params.angular_velocity;
  if constexpr (D == 2) s.angular_velocity[0] = s.angular_velocity[1] = 0;
  return s;
}

template <int D>
RigidPose<D> body_pose(const RigidBodyState<D>& s, const Vec<D, double>& center) {
  RigidPose<D> p;
  p.rotation = quaternion_matrix(s.orientation);
  p.center = center;
  p.translation = s.position - center;
  p.velocity = s.velocity;
  p.angular_velocity = s.angular_velocity;
  return p;
}

template <int D>
void add_container_contact(const Box<D>& container, const Box<D>& box, const RigidBodyState<D>& s,
                           const MassProperties<D>& mp, double omega, double dt, BodyLoad<D>& load) {
  const RigidPose<D> pose = body_pose(s, mp.center);
  const double k = mp.mass * omega * omega, c = mp.mass * omega;
  for (int corner = 0; corner < (1 << D); ++corner) {
    const Vec<D, double> x = pose.place(box_corner<D>(box.lo, box.hi, corner));
    const Vec<D, double> v = pose.velocity_at(x);
    Vec<D, double> f{};
    for (int d = 0; d < D; ++d) {
      const double below = container.lo[d] - x[d], above = x[d] - container.hi[d];
      if (below > 0) f[d] += std::max(0.0, k * below - c * v[d]);
      if (above > 0) f[d] -= std::max(0.0, k * above + c * v[d]);
    }
    if (norm2(f) == 0) continue;
    load.impulse += f * dt;
    add_moment<D>(load.angular_impulse, x, s.position, f * dt);
  }
}

template <int D>
void add_body_contact(const ContactBox<D>& a, const ContactBox<D>& b, double omega, double dt, BodyLoad<D>& load_a,
                      BodyLoad<D>* load_b) {
  const double m = b.mass > 0 ? a.mass * b.mass / (a.mass + b.mass) : a.mass;
  const double k = m * omega * omega, c = m * omega;
  const Vec<D, double> ca = a.pose.center + a.pose.translation, cb = b.pose.center + b.pose.translation;
  // The corners of `of` inside `in`: the push on the corner, out of `in`, and where it acts.
  const auto meet = [&](const ContactBox<D>& of, const ContactBox<D>& in, auto&& push) {
    const std::size_t corners = of.shape ? of.shape->vertices.size() : std::size_t{1} << D;
    for (std::size_t corner = 0; corner < corners; ++corner) {
      const Vec<D, double> x = of.pose.place(of.shape ? of.shape->vertices[corner]
                                                      : box_corner<D>(of.box.lo, of.box.hi, static_cast<int>(corner)));
      const Vec<D, double> X = in.pose.to_rest(x);
      double depth = std::numeric_limits<double>::infinity();
      Vec<D, double> normal{};
      if (in.shape) {
        const SurfaceDistance<D> s = in.shape->solid_distance(X, 0);
        if (!(s.distance < 0)) continue;
        depth = -s.distance;
        normal = s.normal;
      } else {
        int face = -1;
        double sign = 0;
        for (int d = 0; d < D; ++d) {
          const double below = X[d] - in.box.lo[d], above = in.box.hi[d] - X[d];
          if (!(below > 0 && above > 0)) {
            face = -1;
            break;
          }
          if (below < depth) depth = below, face = d, sign = -1;
          if (above < depth) depth = above, face = d, sign = 1;
        }
        if (face < 0) continue;
        normal[face] = sign;
      }
      normal = in.pose.rotate(normal);  // out of `in`, in the world's frame
      const double vn = dot(of.pose.velocity_at(x) - in.pose.velocity_at(x), normal);
      const double f = std::max(0.0, k * depth - c * vn);
      if (f > 0) push(x, normal * (f * dt));
    }
  };
  // a's corners in b: a is pushed out of b, b back.
  meet(a, b, [&](const Vec<D, double>& x, const Vec<D, double>& j) {
    load_a.impulse += j;
    add_moment<D>(load_a.angular_impulse, x, ca, j);
    if (load_b) {
      load_b->impulse -= j;
      add_moment<D>(load_b->angular_impulse, x, cb, j * -1.0);
    }
  });
  // b's corners in a: b is pushed out of a, a back.
  meet(b, a, [&](const Vec<D, double>& x, const Vec<D, double>& j) {
    load_a.impulse -= j;
    add_moment<D>(load_a.angular_impulse, x, ca, j * -1.0);
    if (load_b) {
      load_b->impulse += j;
      add_moment<D>(load_b->angular_impulse, x, cb, j);
    }
  });
}

template <int D>
void advance_body(RigidBodyState<D>& s, const MassProperties<D>& mp, const BodyLoad<D>& load,
                  const Vec<D, double>& gravity, double dt) {
  s.velocity += load.impulse * (1.0 / mp.mass) + gravity * dt;
  // The angular momentum's change in the world's frame, I_w = R I R^T.
  const std::array<double, 9> r = quaternion_matrix(s.orientation);
  const auto inertia_inverse = [&](const Vec<3, double>& v) {
    Vec<3, double> b = times_transposed(r, v);
    for (int a = 0; a < 3; ++a) b[a] /= mp.inertia[a];
    return times(r, b);
  };
  Vec<3, double> spin = times_transposed(r, s.angular_velocity);
  for (int a = 0; a < 3; ++a) spin[a] *= mp.inertia[a];
  const Vec<3, double> momentum = times(r, spin);  // I_w w
  s.angular_velocity += inertia_inverse(load.angular_impulse - cross(s.angular_velocity, momentum) * dt);
  if constexpr (D == 2) s.angular_velocity[0] = s.angular_velocity[1] = 0;
  s.position += s.velocity * dt;
  // q <- exp(dt w / 2) q: exact for a constant w, and unit length kept.
  const double rate = std::sqrt(norm2(s.angular_velocity));
  if (rate > 0) {
    const double half = 0.5 * rate * dt, sh = std::sin(half) / rate;
    const std::array<double, 4> e{std::cos(half), s.angular_velocity[0] * sh, s.angular_velocity[1] * sh,
                                  s.angular_velocity[2] * sh};
    const std::array<double, 4>& q = s.orientation;
    std::array<double, 4> n{
        e[0] * q[0] - e[1] * q[1] - e[2] * q[2] - e[3] * q[3], e[0] * q[1] + e[1] * q[0] + e[2] * q[3] - e[3] * q[2],
        e[0] * q[2] - e[1] * q[3] + e[2] * q[0] + e[3] * q[1], e[0] * q[3] + e[1] * q[2] - e[2] * q[1] + e[3] * q[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] + n[3] * n[3]);
    for (double& c : n) c /= len;
    s.orientation = n;
  }
}

template MassProperties<2> box_mass_properties<2>(const Box<2>&, double);
template MassProperties<3> box_mass_properties<3>(const Box<3>&, double);
template RigidBodyState<2> initial_body_state<2>(const Box<2>&, const BodyParams<2>&);
template RigidBodyState<3> initial_body_state<3>(const Box<3>&, const BodyParams<3>&);
template RigidPose<2> body_pose<2>(const RigidBodyState<2>&, const Vec<2, double>&);
template RigidPose<3> body_pose<3>(const RigidBodyState<3>&, const Vec<3, double>&);
template void add_container_contact<2>(const Box<2>&, const Box<2>&, const RigidBodyState<2>&, const MassProperties<2>&,
                                       double, double, BodyLoad<2>&);
template void add_container_contact<3>(const Box<3>&, const Box<3>&, const RigidBodyState<3>&, const MassProperties<3>&,
                                       double, double, BodyLoad<3>&);
template void add_body_contact<2>(const ContactBox<2>&, const ContactBox<2>&, double, double, BodyLoad<2>&,
                                  BodyLoad<2>*);
template void add_body_contact<3>(const ContactBox<3>&, const ContactBox<3>&, double, double, BodyLoad<3>&,
                                  BodyLoad<3>*);
template void advance_body<2>(RigidBodyState<2>&, const MassProperties<2>&, const BodyLoad<2>&, const Vec<2, double>&,
                              double);
template void advance_body<3>(RigidBodyState<3>&, const MassProperties<3>&, const BodyLoad<3>&, const Vec<3, double>&,
                              double);

}  // namespace sph
