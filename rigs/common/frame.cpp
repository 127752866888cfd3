#include "rigs/common/frame.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rocklab::rigs {

template <int D>
LoadingFrame<D>::LoadingFrame(Simulation<D>& sim, const Vec<D>& lo, const Vec<D>& hi,
                              std::uint16_t wall_material)
    : sim_(&sim) {
  if (sim.walls().size() != 0) throw std::logic_error("the loading frame owns the walls");
  for (int a = 0; a < D; ++a) {
    Wall<D> low, high;
    low.name = std::string(1, "xyz"[a]) + "min";
    high.name = std::string(1, "xyz"[a]) + "max";
    low.normal = Vec<D>::Unit(a);
    low.point = lo;
    high.normal = -Vec<D>::Unit(a);
    high.point = hi;
    low.material = high.material = wall_material;
    sim.addWall(low);
    sim.addWall(high);
  }
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    solid_volume_ += sim.particles().volume(i);
  resetReference();
  apply();
}

template <int D>
double LoadingFrame<D>::length(int axis) const {
  return sim_->wall(2 * axis + 1).point[axis] - sim_->wall(2 * axis).point[axis];
}

template <int D>
double LoadingFrame<D>::faceArea(int axis) const {
  double a = 1.0;
  for (int b = 0; b < D; ++b) {
    if (b != axis) a *= length(b);
  }
  return D == 2 ? a * sim_->particles().thickness : a;
}

template <int D>
double LoadingFrame<D>::stress(int axis) const {
  const double area = faceArea(axis);
  return 0.5 *
         (sim_->wall(2 * axis).normalStress(area) + sim_->wall(2 * axis + 1).normalStress(area));
}

template <int D>
Vec<D> LoadingFrame<D>::interiorStress() const {
  Vec<D> centre;
  for (int a = 0; a < D; ++a) {
    centre[a] = 0.5 * (sim_->wall(2 * a).point[a] + sim_->wall(2 * a + 1).point[a]);
  }
  // One pass over the bodies for every axis: the rig reads all of them at each record.
  Vec<D> sigma = sim_->unbalancedForceMoment(centre) / volume();
  for (int a = 0; a < D; ++a) sigma[a] += stress(a);
  return sigma;
}

template <int D>
double LoadingFrame<D>::force(int axis) const {
  return stress(axis) * faceArea(axis);
}

template <int D>
void LoadingFrame<D>::place(int axis, double lo, double hi) {
  for (const auto& [w, at] : {std::pair{2 * axis, lo}, std::pair{2 * axis + 1, hi}}) {
    Vec<D> p = sim_->wall(w).point;
    p[axis] = at;
    sim_->placeWall(w, p);
  }
  apply();
}

template <int D>
double LoadingFrame<D>::meanStress() const {
  double s = 0.0;
  for (int a = 0; a < D; ++a) s += stress(a);
  return s / D;
}

template <int D>
double LoadingFrame<D>::strain(int axis) const {
  return (reference_[axis] - length(axis)) / reference_[axis];
}

template <int D>
double LoadingFrame<D>::volumetricStrain() const {
  double ref = 1.0, now = 1.0;
  for (int a = 0; a < D; ++a) ref *= reference_[a], now *= length(a);
  return (ref - now) / ref;
}

template <int D>
void LoadingFrame<D>::resetReference() {
  for (int a = 0; a < D; ++a) reference_[a] = length(a);
}

template <int D>
double LoadingFrame<D>::volume() const {
  double v = 1.0;
  for (int a = 0; a < D; ++a) v *= length(a);
  return D == 2 ? v * sim_->particles().thickness : v;
}

template <int D>
double LoadingFrame<D>::porosity() const {
  return 1.0 - solid_volume_ / volume();
}

template <int D>
double LoadingFrame<D>::stressError() const {
  double worst = 0.0;
  for (int a = 0; a < D; ++a) {
    if (axes_[a].mode != Mode::Stress) continue;
    const double target = sim_->wall(2 * a).servo.target(sim_->time());
    const double scale = std::max(std::abs(target), 1.0);
    for (int w : {2 * a, 2 * a + 1}) {
      worst = std::max(worst, std::abs(sim_->wall(w).normalStress(faceArea(a)) - target) / scale);
    }
  }
  return worst;
}

template <int D>
void LoadingFrame<D>::set(int axis, const Axis& a) {
  if (a.mode == Mode::Stress && !(servo_max_speed_ > 0.0)) {
    throw std::logic_error("LoadingFrame: setServo() before a stress-controlled axis");
  }
  axes_[axis] = a;
  for (int w : {2 * axis, 2 * axis + 1}) {
    Wall<D>& wall = sim_->wall(w);
    wall.servo.enabled = a.mode == Mode::Stress;
    wall.servo.target_stress = a.stress;
    wall.servo.target_rate = a.stress_rate;
    wall.servo.t0 = sim_->time();
    wall.servo.alpha = servo_alpha_;
    wall.servo.max_speed = servo_max_speed_;
    if (a.mode == Mode::Fixed) wall.velocity.setZero();
  }
  apply();
}

template <int D>
void LoadingFrame<D>::setServo(double alpha, double max_speed) {
  servo_alpha_ = alpha;
  servo_max_speed_ = max_speed;
  for (int w = 0; w < 2 * D; ++w) {
    sim_->wall(w).servo.alpha = alpha;
    sim_->wall(w).servo.max_speed = max_speed;
  }
}

template <int D>
void LoadingFrame<D>::apply() {
  for (int a = 0; a < D; ++a) {
    const double area = faceArea(a);
    for (int w : {2 * a, 2 * a + 1}) {
      Wall<D>& wall = sim_->wall(w);
      wall.servo.area = area;
      if (axes_[a].mode == Mode::StrainRate) {
        wall.velocity = (0.5 * axes_[a].strain_rate * length(a)) * wall.normal;
      }
    }
  }
}

template <int D>
void LoadingFrame<D>::step() {
  apply();
  if (effect_ && sim_->steps() % effect_interval_ == 0) effect_();
  sim_->step();
}

template class LoadingFrame<2>;
template class LoadingFrame<3>;

}  // namespace rocklab::rigs
