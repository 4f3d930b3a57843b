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

constexpr std::array<double, 9> kIdentity{1, 0, 0, 0, 1, 0, 0, 0, 1};

/// A B for row-major 3 x 3 matrices.
std::array<double, 9> product(const std::array<double, 9>& a, const std::array<double, 9>& b) {
  std::array<double, 9> c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return c;
}

/// The eigenvalues (ascending is not promised) and eigenvectors (the columns of `vectors`, a
/// rotation) of a symmetric 3 x 3 matrix, by cyclic Jacobi rotations.
void symmetric_eigen(std::array<double, 9> a, Vec<3, double>& values, std::array<double, 9>& vectors) {
  vectors = kIdentity;
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
    const double scale = a[0] * a[0] + a[4] * a[4] + a[8] * a[8];
    if (!(off > 1e-30 * scale)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        const double apq = a[3 * p + q];
        if (apq == 0) continue;
        const double theta = (a[3 * q + q] - a[3 * p + p]) / (2 * apq);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), sn = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J (columns p, q)
          const double akp = a[3 * k + p], akq = a[3 * k + q];
          a[3 * k + p] = c * akp - sn * akq;
          a[3 * k + q] = sn * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A (rows p, q)
          const double apk = a[3 * p + k], aqk = a[3 * q + k];
          a[3 * p + k] = c * apk - sn * aqk;
          a[3 * q + k] = sn * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = vectors[3 * k + p], vkq = vectors[3 * k + q];
          vectors[3 * k + p] = c * vkp - sn * vkq;
          vectors[3 * k + q] = sn * vkp + c * vkq;
        }
      }
  }
  values = {{a[0], a[4], a[8]}};
  // A rotation: the third column the cross product of the first two.
  const Vec<3, double> e0{{vectors[0], vectors[3], vectors[6]}}, e1{{vectors[1], vectors[4], vectors[7]}};
  const Vec<3, double> e2 = cross(e0, e1);
  vectors[2] = e2[0], vectors[5] = e2[1], vectors[8] = e2[2];
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
MassProperties<D> shape_mass_properties(const ObstacleShape<D>& shape, double density) {
  SPH_CHECK(!shape.empty() && !shape.inverted, "shape_mass_properties: a solid inside a closed surface");
  MassProperties<D> mp;
  const auto& v = shape.vertices;
  // Sums over the faces' simplices with the origin, taken about a vertex (for round-off).
  const Vec<D, double> o = v[0];
  double volume = 0;
  Vec<D, double> moment{};
  if constexpr (D == 2) {
    double polar = 0;  // the second moment of area about o
    for (const auto& e : shape.faces) {
      const Vec<2, double> a = v[e[0]] - o, b = v[e[1]] - o;
      const double c = a[0] * b[1] - a[1] * b[0];
      volume += c / 2;
      moment += (a + b) * (c / 6);
      polar += c * (dot(a, a) + dot(a, b) + dot(b, b)) / 12;
    }
    const Vec<2, double> centroid = moment * (1 / volume);
    mp.mass = density * volume;
    mp.center = o + centroid;
    const double iz = density * (polar - volume * dot(centroid, centroid));
    mp.inertia = {{iz, iz, iz}};
  } else {
    std::array<double, 9> second{};  // integral of x x^T dV about o
    for (const auto& t : shape.faces) {
      const Vec<3, double> a = v[t[0]] - o, b = v[t[1]] - o, c = v[t[2]] - o;
      const double vol = dot(a, cross(b, c)) / 6;
      volume += vol;
      const Vec<3, double> sum = a + b + c;
      moment += sum * (vol / 4);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          second[3 * i + j] += vol / 20 * (sum[i] * sum[j] + a[i] * a[j] + b[i] * b[j] + c[i] * c[j]);
    }
    const Vec<3, double> centroid = moment * (1 / volume);
    mp.mass = density * volume;
    mp.center = o + centroid;
    std::array<double, 9> inertia{};  // about the centre: rho (tr(C) 1 - C), C = second - V c c^T
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) second[3 * i + j] -= volume * centroid[i] * centroid[j];
    const double trace = second[0] + second[4] + second[8];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) inertia[3 * i + j] = density * ((i == j ? trace : 0.0) - second[3 * i + j]);
    symmetric_eigen(inertia, mp.inertia, mp.axes);
  }
  return mp;
}

template <int D>
std::array<double, 9> principal_frame(const RigidBodyState<D>& s, const MassProperties<D>& mp) {
  const std::array<double, 9> r = quaternion_matrix(s.orientation);
  return mp.axes == kIdentity ? r : product(r, mp.axes);  // (a box's: R itself, bit for bit)
}

template <int D>
RigidBodyState<D> initial_body_state(const Vec<D, double>& center, const BodyParams<D>& params) {
  RigidBodyState<D> s;
  s.position = center;
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
                           const MassProperties<D>& mp, double omega, double dt, BodyLoad<D>& load,
                           const ObstacleShape<D>* shape) {
  const RigidPose<D> pose = body_pose(s, mp.center);
  const double k = mp.mass * omega * omega, c = mp.mass * omega;
  for_each_contact_point<D>(box, shape, pose, [&](const Vec<D, double>& x) {
    const Vec<D, double> v = pose.velocity_at(x);
    Vec<D, double> f{};
    for (int d = 0; d < D; ++d) {
      const double below = container.lo[d] - x[d], above = x[d] - container.hi[d];
      if (below > 0) f[d] += std::max(0.0, k * below - c * v[d]);
      if (above > 0) f[d] -= std::max(0.0, k * above + c * v[d]);
    }
    if (norm2(f) == 0) return;
    load.impulse += f * dt;
    add_moment<D>(load.angular_impulse, x, s.position, f * dt);
  });
}

template <int D>
WallDepth container_depth(const Box<D>& container, const Box<D>& box, const RigidBodyState<D>& s,
                          const MassProperties<D>& mp, const ObstacleShape<D>* shape) {
  WallDepth deepest;
  for_each_contact_point<D>(box, shape, body_pose(s, mp.center), [&](const Vec<D, double>& x) {
    for (int d = 0; d < D; ++d) {
      const double below = container.lo[d] - x[d], above = x[d] - container.hi[d];
      if (below > deepest.depth) deepest = {below, d, false};
      if (above > deepest.depth) deepest = {above, d, true};
    }
  });
  return deepest;
}

template <int D>
double container_contact_energy(const Box<D>& container, const Box<D>& box, const RigidBodyState<D>& s,
                                const MassProperties<D>& mp, double omega, const ObstacleShape<D>* shape) {
  double e = 0;
  for_each_contact_point<D>(box, shape, body_pose(s, mp.center), [&](const Vec<D, double>& x) {
    for (int d = 0; d < D; ++d) {
      const double pen = std::max({container.lo[d] - x[d], x[d] - container.hi[d], 0.0});
      e += 0.5 * mp.mass * omega * omega * pen * pen;
    }
  });
  return e;
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
std::array<double, 9> world_inverse_inertia(const RigidBodyState<D>& s, const MassProperties<D>& mp) {
  std::array<double, 9> out{};
  if constexpr (D == 2) {
    out[8] = 1.0 / mp.inertia[2];
  } else {
    const std::array<double, 9> r = principal_frame(s, mp);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        for (int k = 0; k < 3; ++k) out[a * 3 + b] += r[a * 3 + k] * r[b * 3 + k] / mp.inertia[k];
  }
  return out;
}

template <int D>
void advance_velocities(RigidBodyState<D>& s, const MassProperties<D>& mp, const BodyLoad<D>& load,
                        const Vec<D, double>& gravity, double dt) {
  s.velocity += load.impulse * (1.0 / mp.mass) + gravity * dt;
  // The angular momentum's change in the world's frame, I_w = R I R^T (R to the principal axes).
  const std::array<double, 9> r = principal_frame(s, mp);
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
}

template <int D>
void advance_body(RigidBodyState<D>& s, const MassProperties<D>& mp, const BodyLoad<D>& load,
                  const Vec<D, double>& gravity, double dt) {
  advance_velocities(s, mp, load, gravity, dt);
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
template RigidBodyState<2> initial_body_state<2>(const Vec<2, double>&, const BodyParams<2>&);
template RigidBodyState<3> initial_body_state<3>(const Vec<3, double>&, const BodyParams<3>&);
template MassProperties<2> shape_mass_properties<2>(const ObstacleShape<2>&, double);
template MassProperties<3> shape_mass_properties<3>(const ObstacleShape<3>&, double);
template std::array<double, 9> principal_frame<2>(const RigidBodyState<2>&, const MassProperties<2>&);
template std::array<double, 9> principal_frame<3>(const RigidBodyState<3>&, const MassProperties<3>&);
template std::array<double, 9> world_inverse_inertia<2>(const RigidBodyState<2>&, const MassProperties<2>&);
template std::array<double, 9> world_inverse_inertia<3>(const RigidBodyState<3>&, const MassProperties<3>&);
template WallDepth container_depth<2>(const Box<2>&, const Box<2>&, const RigidBodyState<2>&, const MassProperties<2>&,
                                      const ObstacleShape<2>*);
template WallDepth container_depth<3>(const Box<3>&, const Box<3>&, const RigidBodyState<3>&, const MassProperties<3>&,
                                      const ObstacleShape<3>*);
template double container_contact_energy<2>(const Box<2>&, const Box<2>&, const RigidBodyState<2>&,
                                            const MassProperties<2>&, double, const ObstacleShape<2>*);
template double container_contact_energy<3>(const Box<3>&, const Box<3>&, const RigidBodyState<3>&,
                                            const MassProperties<3>&, double, const ObstacleShape<3>*);
template RigidPose<2> body_pose<2>(const RigidBodyState<2>&, const Vec<2, double>&);
template RigidPose<3> body_pose<3>(const RigidBodyState<3>&, const Vec<3, double>&);
template void add_container_contact<2>(const Box<2>&, const Box<2>&, const RigidBodyState<2>&, const MassProperties<2>&,
                                       double, double, BodyLoad<2>&, const ObstacleShape<2>*);
template void add_container_contact<3>(const Box<3>&, const Box<3>&, const RigidBodyState<3>&, const MassProperties<3>&,
                                       double, double, BodyLoad<3>&, const ObstacleShape<3>*);
template void add_body_contact<2>(const ContactBox<2>&, const ContactBox<2>&, double, double, BodyLoad<2>&,
                                  BodyLoad<2>*);
template void add_body_contact<3>(const ContactBox<3>&, const ContactBox<3>&, double, double, BodyLoad<3>&,
                                  BodyLoad<3>*);
template void advance_velocities<2>(RigidBodyState<2>&, const MassProperties<2>&, const BodyLoad<2>&,
                                    const Vec<2, double>&, double);
template void advance_velocities<3>(RigidBodyState<3>&, const MassProperties<3>&, const BodyLoad<3>&,
                                    const Vec<3, double>&, double);
template void advance_body<2>(RigidBodyState<2>&, const MassProperties<2>&, const BodyLoad<2>&, const Vec<2, double>&,
                              double);
template void advance_body<3>(RigidBodyState<3>&, const MassProperties<3>&, const BodyLoad<3>&, const Vec<3, double>&,
                              double);

}  // namespace sph
