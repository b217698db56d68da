// Pinocchio's own templated algorithms on casadi::SX, saved as casadi Functions.
//
// Usage: _pin_casadi MODEL.txt OUTDIR
//   MODEL.txt  a pinocchio Model written by Python `model.saveToText(path)`
//   OUTDIR     existing directory; receives pin_vel.casadi, pin_aba.casadi, pin_rnea.casadi
//
// With nj = model.njoints - 1 (joints other than the universe):
//   pin_vel(q[nq], v[nv]) -> V[6*nj]
//       each joint's spatial velocity in its LOCAL frame, [linear; angular] (data.v[1..]).
//   pin_aba(q, v, tau[nv], dyn[10*nj], fext[6*nj], g[3]) -> ddq[nv]
//       pinocchio::aba, Convention::LOCAL; joint i's inertia is
//       InertiaTpl::FromDynamicParameters(dyn[10*(i-1):10*i]) (order of
//       pin.Inertia.toDynamicParameters(); all zero = a massless joint), fext[6*(i-1):6*i] is the force on joint i in its
//       LOCAL frame [linear; angular], and the model gravity's linear part is g [m/s^2].
//   pin_rnea(q, v, a[nv], dyn, fext, g) -> tau[nv]
//       pinocchio::rnea with the same inputs.
//
// The program does not depend on the model: it is built once per pin/casadi version.
// Exit status: 0 on success, 2 on bad usage, 1 on any error (message on stderr).

#include <casadi/casadi.hpp>

#include <pinocchio/autodiff/casadi.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/serialization.hpp>

#include <exception>
#include <iostream>
#include <string>
#include <vector>

namespace
{
  using SX = ::casadi::SX;
  using ADModel = pinocchio::ModelTpl<SX>;
  using ADData = pinocchio::DataTpl<SX>;
  using VectorSX = Eigen::Matrix<SX, Eigen::Dynamic, 1>;
  using Vector3SX = Eigen::Matrix<SX, 3, 1>;
  using Vector6SX = Eigen::Matrix<SX, 6, 1>;
  using ForceSX = pinocchio::ForceTpl<SX>;

  VectorSX to_eigen(const SX & x)
  {
    VectorSX out(x.size1());
    pinocchio::casadi::copy(x, out);
    return out;
  }

  SX to_casadi(const VectorSX & x)
  {
    SX out(x.size(), 1);
    pinocchio::casadi::copy(x, out);
    return out;
  }

  // InertiaTpl::FromDynamicParameters, except that a massless joint (mass 0, first moment 0:
  // a carriage joint that only carries a placement) gives the zero inertia instead of NaN
  // (the lever h/m is taken as h/1 there).
  pinocchio::InertiaTpl<SX> from_dynamic_parameters(const Eigen::Matrix<SX, 10, 1> & p)
  {
    using Inertia = pinocchio::InertiaTpl<SX>;
    const SX & mass = p[0];
    const SX safe_mass = SX::if_else(mass == 0, SX(1), mass);
    Inertia::Vector3 lever = p.segment<3>(1) / safe_mass;
    return Inertia(
      mass, lever,
      Inertia::Symmetric3(p.segment<6>(4)) + Inertia::Symmetric3::AlphaSkewSquare(mass, lever));
  }

  // The model's inertias from dyn, its gravity from g (both symbolic).
  void set_parameters(ADModel & model, const VectorSX & dyn, const VectorSX & g)
  {
    for (pinocchio::JointIndex i = 1; i < (pinocchio::JointIndex)model.njoints; ++i)
    {
      Eigen::Matrix<SX, 10, 1> p = dyn.segment<10>(10 * ((Eigen::Index)i - 1));
      model.inertias[i] = from_dynamic_parameters(p);
    }
    Vector3SX g3 = g.head<3>();
    model.gravity.linear(g3);
  }

  std::vector<ForceSX> forces(const ADModel & model, const VectorSX & fext)
  {
    std::vector<ForceSX> out((std::size_t)model.njoints, ForceSX::Zero());
    for (pinocchio::JointIndex i = 1; i < (pinocchio::JointIndex)model.njoints; ++i)
    {
      Vector6SX f = fext.segment<6>(6 * ((Eigen::Index)i - 1));
      out[i] = ForceSX(f);
    }
    return out;
  }
} // namespace

int main(int argc, char ** argv)
{
  if (argc != 3)
  {
    std::cerr << "usage: " << argv[0] << " MODEL.txt OUTDIR" << std::endl;
    return 2;
  }
  const std::string model_path = argv[1];
  const std::string out_dir = argv[2];
  try
  {
    pinocchio::Model model;
    model.loadFromText(model_path);
    const ADModel base = model.cast<SX>();
    const Eigen::Index nq = base.nq, nv = base.nv, nj = base.njoints - 1;

    const SX q = SX::sym("q", nq), v = SX::sym("v", nv), u = SX::sym("u", nv);
    const SX dyn = SX::sym("dyn", 10 * nj), fext = SX::sym("fext", 6 * nj), g = SX::sym("g", 3);
    const VectorSX q_e = to_eigen(q), v_e = to_eigen(v), u_e = to_eigen(u);
    const VectorSX dyn_e = to_eigen(dyn), fext_e = to_eigen(fext), g_e = to_eigen(g);

    {
      ADData data(base);
      pinocchio::forwardKinematics(base, data, q_e, v_e);
      VectorSX vel(6 * nj);
      for (Eigen::Index i = 1; i <= nj; ++i)
        vel.segment<6>(6 * (i - 1)) = data.v[(std::size_t)i].toVector();
      ::casadi::Function(
        "pin_vel", {q, v}, {to_casadi(vel)}, {"q", "v"}, {"V"})
        .save(out_dir + "/pin_vel.casadi");
    }

    ADModel am = base;
    set_parameters(am, dyn_e, g_e);
    const std::vector<ForceSX> f = forces(am, fext_e);
    {
      ADData data(am);
      pinocchio::aba(am, data, q_e, v_e, u_e, f, pinocchio::Convention::LOCAL);
      ::casadi::Function(
        "pin_aba", {q, v, u, dyn, fext, g}, {to_casadi(data.ddq)},
        {"q", "v", "tau", "dyn", "fext", "g"}, {"ddq"})
        .save(out_dir + "/pin_aba.casadi");
    }
    {
      ADData data(am);
      pinocchio::rnea(am, data, q_e, v_e, u_e, f);
      ::casadi::Function(
        "pin_rnea", {q, v, u, dyn, fext, g}, {to_casadi(data.tau)},
        {"q", "v", "a", "dyn", "fext", "g"}, {"tau"})
        .save(out_dir + "/pin_rnea.casadi");
    }
  }
  catch (const std::exception & exc)
  {
    std::cerr << "pin_casadi generator: " << model_path << ": " << exc.what() << std::endl;
    return 1;
  }
  return 0;
}
