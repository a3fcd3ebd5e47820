#pragma once
// Seed 002's component equations (21) for the car, exactly as printed (002 L1490-1496), as an estimator beside
// the bank ("POLY3-21"). The engine's POLY3 is the general degree-3 filter (9)-(10) (002 L1442, L1386); for the
// Taylor model (20) its components differ from the printed (21) in two terms:
//   mean:  (v/3l)(3 p_dd m_d + m_d^3)  from (9), E[x^3] = 3 p*m + m^3 (6)  --  printed (v/3l)(3 p_d + m_d^3)
//          (the factor m_d dropped; p_d read as p_dd, the d-component of the variance vector p of (9));
//   P:     dp_fd = (v/l)(1 + p_dd + m_d^2) p_dd - ...  from 3 a3 (p*P) in (10)  --  printed without (v/l) p_dd^2.
// dp_ff and dp_dd are as (10) gives them. Gain P, i.e. V = I, as printed. Discretized like the bank's filters
// (kernels/filters/filter_step.hpp): update with dy, then an Euler step of the printed drift terms (which are not
// of the form J P + P J^T, so P += D dt rather than the congruence).
#include "engine/reference_estimator.hpp"
#include "kernels/bank.hpp"
#include "kernels/filters/filter_step.hpp"
#include "kernels/for_each_member.hpp"
#include "models/car_model.hpp"

#include <Kokkos_Core.hpp>

#include <cstdint>
#include <string>

namespace kushner {

namespace detail {

template <class MemSpace>
struct PrintedCarFilterStep {
  double v_over_l, u;
  BankVector<MemSpace> dy, m;
  BankSymmetric<MemSpace> P;
  BankScalar<Status, MemSpace> status;
  double t, dt;
  std::uint32_t step;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (status(member) != Status::ok) return;
    Vec<2> mm = load<2>(m, member);
    Mat<2, 2> Pm = load_symmetric<2>(P, member);
    const StepInput<2> in{t, dt, step, load<2>(dy, member), Mat<2, 2>::identity()};
    Vec<2> weighted_innovation;
    if (!kalman_update(ObservationLinearization<2, 2>{mm, Mat<2, 2>::identity()}, in, mm, Pm, weighted_innovation)) {
      status(member) = Status::not_positive_definite;
      return;
    }
    const double md = mm[1], pfd = Pm(0, 1), pdd = Pm(1, 1), c = v_over_l;
    const Vec<2> a{{c * md + c / 3.0 * (3.0 * pdd + md * md * md), u}};  // (21), first two lines
    Mat<2, 2> D;                                                         // (21), the P lines without -P^2
    D(0, 0) = 2.0 * c * pfd * pdd + 2.0 * c * pfd + 2.0 * c * md * md * pfd;
    D(0, 1) = D(1, 0) = c * pdd + c * md * md * pdd;
    D(1, 1) = 0.0;
    mm += a * dt;
    Pm = symmetrize(Pm + D * dt);
    Mat<2, 2> L;
    if (!(all_finite(mm) && all_finite(Pm))) {
      status(member) = Status::non_finite;
      return;
    }
    if (semidefinite_cholesky(Pm, L, covariance_tolerance) == Definiteness::indefinite) {
      status(member) = Status::not_positive_definite;
      return;
    }
    store(m, member, mm);
    store_symmetric(P, member, Pm);
  }
};

}  // namespace detail

template <class ExecSpace>
class PrintedCarFilter final : public ReferenceEstimator<typename ExecSpace::memory_space> {
 public:
  using MemSpace = typename ExecSpace::memory_space;

  PrintedCarFilter(const ExecSpace& space, const CarTaylor3Model& model, long members)
      : space_(space),
        v_over_l_(model.v / model.l),
        u_(model.u),
        m_("kushner::printed_car_m", members, 2),
        P_("kushner::printed_car_P", members, 3),
        status_("kushner::printed_car_status", members) {
    const auto m = Kokkos::create_mirror_view(m_);
    const auto P = Kokkos::create_mirror_view(P_);
    for (long member = 0; member < members; ++member) {
      for (int i = 0; i < 2; ++i) m(member, i) = model.prior_mean[i];
      for (int i = 0; i < 2; ++i)
        for (int j = i; j < 2; ++j) P(member, packed_index(2, i, j)) = model.prior_cov(i, j);
    }
    Kokkos::deep_copy(m_, m);
    Kokkos::deep_copy(P_, P);
  }

  std::string name() const override { return "POLY3-21"; }
  void advance(long k, double t, double dt, const BankVector<MemSpace>& dy) override {
    parallel_for_members("kushner::printed_car_filter_step", space_, m_.extent(0),
                         detail::PrintedCarFilterStep<MemSpace>{v_over_l_, u_, dy, m_, P_, status_, t, dt,
                                                                static_cast<std::uint32_t>(k)});
  }
  BankVector<MemSpace> mean() const override { return m_; }
  BankSymmetric<MemSpace> covariance() const override { return P_; }
  BankScalar<Status, MemSpace> status() const override { return status_; }
  Fields describe() const override {
    return {{"kind", std::string("printed equations")},
            {"note",
             std::string("seed 002 (21) as printed: mean term (v/3l)(3 p_dd + m_d^3), dp_fd without (v/l) p_dd^2")}};
  }

 private:
  ExecSpace space_;
  double v_over_l_, u_;
  BankVector<MemSpace> m_;
  BankSymmetric<MemSpace> P_;
  BankScalar<Status, MemSpace> status_;
};

}  // namespace kushner
