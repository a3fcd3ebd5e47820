#pragma once
// Basin's terpolymerization reactor, seed 002 ACC03 (18)-(19) (002 L1739-1770): ten bilinear states
// x = (C_m1, C_m2, C_m3, C*, mu_P, mu_Q, mu_R, lambda_100, lambda_010, lambda_001), all observed,
//   dx = f(x) dt + q dw,   dy = x dt + r dv,
// f as in (18) (drift() below, equation by equation). All parameters 1 as in the paper (002 L1770; K_32 and
// K_L3 are listed there but do not occur in (18)); truth from x(0) = 0, filters from m(0) = 0.5, P(0) = I.
// The paper has no state noise (q = 0) and "realizes" the observation noises as sin t; here they are Brownian
// with V = I (r = 1, the gain printed as P) unless sine_observation_noise = 1 (`kushner reproduce basin-terpolymer`).
// It states no horizon.
#include "core/errors.hpp"
#include "core/small_matrix.hpp"
#include "models/drift_forms.hpp"
#include "models/initial_law.hpp"
#include "models/sine_observation_noise.hpp"

namespace kushner {

struct TerpolymerModel : InitialLaw<10>, SineObservationNoiseOption {
  static constexpr int state_dim = 10, obs_dim = 10, noise_dim = 10, control_dim = 0;
  static constexpr bool discrete_time = false;
  static constexpr bool linear_observation = true;
  static constexpr const char* name = "terpolymer";
  static constexpr const char* description =
      "Basin's terpolymerization reactor: 10 bilinear states, all observed (ACC03 (18)), dy = x dt + r dv";
  static constexpr int num_bilinear_terms = 32;
  using Control = Vec<control_dim>;

  double V = 1.0, theta = 1.0;                             // reactor volume, residence time
  double F_m1 = 1.0, F_m2 = 1.0, F_m3 = 1.0, F_cat = 1.0;  // net molar inflows dDelta/dt of monomers and catalyst
  double K_L1 = 1.0, K_L2 = 1.0, K_11 = 1.0, K_21 = 1.0, K_31 = 1.0, K_12 = 1.0, K_22 = 1.0, K_13 = 1.0;
  double K_d = 1.0, K_t1 = 1.0, K_t2 = 1.0, K_t3 = 1.0;
  double q = 0.0, r = 1.0;

  TerpolymerModel() {
    x0_mean = Vec<10>::zero();
    x0_cov = Mat<10, 10>::zero();
    prior_mean = Vec<10>::constant(0.5);
    prior_cov = Mat<10, 10>::identity();
  }

  template <class Visitor>
  void parameters(Visitor&& v) {
    v("V", V, "reactor volume");
    v("theta", theta, "residence time");
    v("F_m1", F_m1, "net molar inflow of monomer 1");
    v("F_m2", F_m2, "net molar inflow of monomer 2");
    v("F_m3", F_m3, "net molar inflow of monomer 3");
    v("F_cat", F_cat, "net molar inflow of active catalyst");
    v("K_L1", K_L1, "rate constant");
    v("K_L2", K_L2, "rate constant");
    v("K_11", K_11, "rate constant");
    v("K_21", K_21, "rate constant");
    v("K_31", K_31, "rate constant");
    v("K_12", K_12, "rate constant");
    v("K_22", K_22, "rate constant");
    v("K_13", K_13, "rate constant");
    v("K_d", K_d, "catalyst deactivation rate");
    v("K_t1", K_t1, "termination rate of mu_P");
    v("K_t2", K_t2, "termination rate of mu_Q");
    v("K_t3", K_t3, "termination rate of mu_R");
    v("q", q, "process noise intensity on every state (paper: 0)");
    v("r", r, "observation noise intensity on every state");
    sine_observation_noise_parameter(v);
    initial_law_parameters(v);
  }

  void validate() const {
    KUSHNER_INPUT_REQUIRE(V != 0.0 && theta != 0.0, "V, theta: must not be 0 (got " << V << ", " << theta << ")");
    validate_sine_observation_noise();
  }

  /// Seed 002 ACC03 (18).
  KOKKOS_INLINE_FUNCTION Vec<10> drift(double, const Vec<10>& x, const Control&) const {
    const double c1 = x[0], c2 = x[1], c3 = x[2], cs = x[3], mp = x[4], mq = x[5], mr = x[6];
    const double out = 1.0 / theta;
    return {{F_m1 / V - (out + K_L1 * cs + K_11 * mp + K_21 * mq + K_31 * mr) * c1,
             F_m2 / V - (out + K_L2 * cs + K_12 * mp + K_22 * mq) * c2, F_m3 / V - (out + K_13 * mp) * c3,
             F_cat / V - (out + K_d + K_L1 * c1 + K_L2 * c2) * cs,
             (-out - K_t1) * mp + K_L1 * c1 * cs - (K_12 * c2 + K_13 * c3) * mp + K_21 * c1 * mq + K_31 * c1 * mr,
             -out * mq + K_L2 * c2 * cs - (K_21 * c1 + K_t2) * mq + K_12 * c2 * mp,
             -out * mr - (K_31 * c1 + K_t3) * mr + K_13 * c3 * mp,
             -out * x[7] + K_L1 * c1 * cs + K_L2 * c2 * cs + K_11 * c1 * mp + K_21 * c1 * mq + K_31 * c1 * mr,
             -out * x[8] + K_L1 * c1 * cs + K_L2 * c2 * cs + K_12 * c2 * mp + K_22 * c2 * mq,
             -out * x[9] + (K_L1 * c1 + K_L2 * c2) * cs + K_13 * c3 * mp}};
  }

  /// (18) as a0 + a1 x + 32 bilinear terms c x_i x_j, read off the products in drift(): the tensor form of BILIN.
  KOKKOS_INLINE_FUNCTION QuadraticPolynomial<10, num_bilinear_terms> drift_quadratic_polynomial(double) const {
    QuadraticPolynomial<10, num_bilinear_terms> f;
    const double out = 1.0 / theta;
    f.a0 = Vec<10>{{F_m1 / V, F_m2 / V, F_m3 / V, F_cat / V, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0}};
    f.a1 = Mat<10, 10>::diagonal(-out);
    f.a1(3, 3) -= K_d;
    f.a1(4, 4) -= K_t1;
    f.a1(5, 5) -= K_t2;
    f.a1(6, 6) -= K_t3;
    enum : int { c1 = 0, c2, c3, cs, mp, mq, mr, l100, l010, l001 };
    f.add(c1, c1, cs, -K_L1);
    f.add(c1, c1, mp, -K_11);
    f.add(c1, c1, mq, -K_21);
    f.add(c1, c1, mr, -K_31);
    f.add(c2, c2, cs, -K_L2);
    f.add(c2, c2, mp, -K_12);
    f.add(c2, c2, mq, -K_22);
    f.add(c3, c3, mp, -K_13);
    f.add(cs, c1, cs, -K_L1);
    f.add(cs, c2, cs, -K_L2);
    f.add(mp, c1, cs, K_L1);
    f.add(mp, c2, mp, -K_12);
    f.add(mp, c3, mp, -K_13);
    f.add(mp, c1, mq, K_21);
    f.add(mp, c1, mr, K_31);
    f.add(mq, c2, cs, K_L2);
    f.add(mq, c1, mq, -K_21);
    f.add(mq, c2, mp, K_12);
    f.add(mr, c1, mr, -K_31);
    f.add(mr, c3, mp, K_13);
    f.add(l100, c1, cs, K_L1);
    f.add(l100, c2, cs, K_L2);
    f.add(l100, c1, mp, K_11);
    f.add(l100, c1, mq, K_21);
    f.add(l100, c1, mr, K_31);
    f.add(l010, c1, cs, K_L1);
    f.add(l010, c2, cs, K_L2);
    f.add(l010, c2, mp, K_12);
    f.add(l010, c2, mq, K_22);
    f.add(l001, c1, cs, K_L1);
    f.add(l001, c2, cs, K_L2);
    f.add(l001, c3, mp, K_13);
    return f;
  }

  KOKKOS_INLINE_FUNCTION Mat<10, 10> drift_jacobian(double t, const Vec<10>& x, const Control&) const {
    const auto f = drift_quadratic_polynomial(t);
    Mat<10, 10> J = f.a1;
    for (int k = 0; k < f.num_terms; ++k) {
      J(f.term[k].k, f.term[k].i) += f.term[k].c * x[f.term[k].j];
      J(f.term[k].k, f.term[k].j) += f.term[k].c * x[f.term[k].i];
    }
    return J;
  }
  KOKKOS_INLINE_FUNCTION Mat<10, 10> drift_hessian(double t, const Vec<10>&, const Control&, int component) const {
    const auto f = drift_quadratic_polynomial(t);
    Mat<10, 10> H = Mat<10, 10>::zero();
    for (int k = 0; k < f.num_terms; ++k) {
      if (f.term[k].k != component) continue;
      H(f.term[k].i, f.term[k].j) += f.term[k].c;
      H(f.term[k].j, f.term[k].i) += f.term[k].c;
    }
    return H;
  }
  KOKKOS_INLINE_FUNCTION Mat<10, 10> diffusion(double, const Vec<10>&) const { return Mat<10, 10>::diagonal(q); }
  KOKKOS_INLINE_FUNCTION Vec<10> observation(double, const Vec<10>& x) const { return x; }
  KOKKOS_INLINE_FUNCTION Mat<10, 10> observation_jacobian(double, const Vec<10>&) const {
    return Mat<10, 10>::identity();
  }
  KOKKOS_INLINE_FUNCTION Mat<10, 10> observation_hessian(double, const Vec<10>&, int) const {
    return Mat<10, 10>::zero();
  }
  KOKKOS_INLINE_FUNCTION Mat<10, 10> observation_noise(double) const { return Mat<10, 10>::diagonal(r); }

  /// A(x) x + b with A_ki = a1_ki + sum_j a2_kij x_j (a2 symmetric, so each product is split evenly between its
  /// two variables), b = a0.
  KOKKOS_INLINE_FUNCTION SdcDrift<10> sdc_drift(double t, const Vec<10>& x) const {
    const auto f = drift_quadratic_polynomial(t);
    SdcDrift<10> s{f.a1, f.a0};
    for (int k = 0; k < f.num_terms; ++k) {
      s.A(f.term[k].k, f.term[k].i) += 0.5 * f.term[k].c * x[f.term[k].j];
      s.A(f.term[k].k, f.term[k].j) += 0.5 * f.term[k].c * x[f.term[k].i];
    }
    return s;
  }
};

}  // namespace kushner
