// How far apart are the energy-consistent RNE (default) and the paper's eq. 18 (inertia frozen
// at each instant) on an arm? Usage: 03_paper_vs_consistent robot.json data.csv
#include <iostream>
#include <random>

#include <softrne/fit/arm_fit.hpp>
#include <softrne/signals/savitzky_golay.hpp>
#include <softrne/io/robot_json.hpp>
int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: " << argv[0] << " robot.json data.csv\n";
    return 2;
  }
  auto spec = softrne::io::read_robot_json(argv[1]);
  auto data = softrne::io::read_dataset(argv[2], spec, true);
  auto a = softrne::build_arm(spec);
  auto b = a;
  b.inertia_rate = softrne::InertiaRate::PaperFrozen;
  auto ca = a.make_chain<double>(), cb = b.make_chain<double>();
  auto da = ca.make_data(), db = cb.make_data();
  // along the measured trajectory (SG derivatives)
  softrne::signals::SgOptions sg;
  Eigen::MatrixXd q, qd, qdd;
  softrne::signals::savgol(data.t, data.angles, sg, q, qd, qdd);
  double maxd = 0, maxt = 0;
  for (int i = 0; i < q.rows(); ++i) {
    Eigen::VectorXd x = q.row(i).transpose(), v = qd.row(i).transpose(), w = qdd.row(i).transpose();
    Eigen::VectorXd ta = softrne::rnea(ca, da, x, v, w);
    Eigen::VectorXd tb = softrne::rnea(cb, db, x, v, w);
    maxd = std::max(maxd, (ta - tb).cwiseAbs().maxCoeff());
    maxt = std::max(maxt, ta.cwiseAbs().maxCoeff());
  }
  std::cout << "max |tau_consistent - tau_paper| along the measured trajectory: " << maxd
            << " N m (max |tau| " << maxt << ")\n";
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1.5, 1.5), V(-3, 3);
  double maxr = 0;
  for (int k = 0; k < 1000; ++k) {
    Eigen::VectorXd x(6), v(6), w = Eigen::VectorXd::Zero(6);
    for (int i = 0; i < 6; ++i) {
      x(i) = U(rng);
      v(i) = V(rng);
    }
    Eigen::VectorXd ta = softrne::rnea(ca, da, x, v, w);
    Eigen::VectorXd tb = softrne::rnea(cb, db, x, v, w);
    maxr = std::max(maxr, (ta - tb).cwiseAbs().maxCoeff());
  }
  std::cout << "max difference at 1000 random states (|q|<=1.5 rad, |qd|<=3 rad/s): " << maxr
            << " N m\n";
  softrne::sim::ArmSimulationOptions o;
  o.cvode.rtol = 1e-8;
  o.cvode.atol = 1e-9;
  auto sa = softrne::fit::simulate_dataset(a, data, o),
       sb = softrne::fit::simulate_dataset(b, data, o);
  std::cout << "simulated trajectory (" << data.t(data.t.size() - 1)
            << " s): max |q_consistent - q_paper| = "
            << (sa.angles - sb.angles).cwiseAbs().maxCoeff() << " rad, mean "
            << (sa.angles - sb.angles).cwiseAbs().mean() << "\n";
}
