// Potential energy of one Super-Helix guide (Lansink 2010 §4.1.1.3, §4.1.2):
//   E = E_elastic + E_gravity + E_collision
// E_elastic = Σ_Q ℓ_Q [E I1/2 (κ1 − κ1⁰)² + E I2/2 (κ2 − κ2⁰)² + μ J/2 (τ − τ⁰)²], I1 = π a b³/4,
//             I2 = π b a³/4, J = π a b (a² + b²)/4, μ = E/(2(1 + σ));
// E_gravity = ρ S g ∫ (y(s) − y(0)) ds in closed form (y is up), S = π a b;
// E_collision = Δs Σ_samples Σ_shapes ½ k max(dent + extra, 0)², samples every CollisionStep after the
//               root, extra = volume · (y_follicle − y_min)/(y_max − y_min) (layered envelopes).
// Joules throughout.
#pragma once

#include <span>
#include <vector>

#include "libcore/config/params.h"
#include "libcore/physics/super_helix.h"

namespace hairgen {

// Penetration depth (metres, positive inside) of `p` into a shape, as the thesis defines it per kind.
double penetration(const CollisionShape& shape, const glm::dvec3& p);
// A radius about a shape's centre beyond which no point of it lies.
double boundingRadius(const CollisionShape& shape);

struct EnergyTerms {
  double elastic = 0.0, gravity = 0.0, collision = 0.0;
  double total() const { return elastic + gravity + collision; }
};

class StrandEnergy {
 public:
  // `envelope` is the follicle's height fraction in [0, 1] between the lowest and highest follicle.
  StrandEnergy(const Hairstyle& style, const Collision& collision, const RodFrame& root, double envelope);

  double operator()(std::span<const double> q) const { return terms(q).total(); }
  EnergyTerms terms(std::span<const double> q) const;
  // The energy and its gradient ∂E/∂q, `gradient` sized like q: the derivatives of the same closed forms,
  // in one walk up the rod and one back (strand_energy.cpp). The value is operator()'s, bit for bit. Not
  // for two threads at once on one StrandEnergy (it keeps the walk's samples in scratch arrays).
  double valueAndGradient(std::span<const double> q, std::span<double> gradient) const;

  // The rest shape's coordinates (the minimiser's start) and the energy scale used for Epsilon:
  // ρ S g L²/2 (the strand's weight times half its length) + E I1 / L (bending it by one radian).
  std::vector<double> restCoordinates() const;
  double energyScale() const;
  // Initial Rosenbrock steps: a quarter radian of bend or twist over each element.
  std::vector<double> initialSteps() const;
  // The inverse of the elastic energy's curvature along each coordinate, 1/(2 ℓ · E I/2 or μ J/2):
  // the quasi-Newton minimiser's first inverse-Hessian estimate (exact without gravity and contact).
  std::vector<double> inverseStiffness() const;

 private:
  struct Shape {
    CollisionShape shape;
    double extra;
    double reach;   // bounding radius + extra: a point farther from the centre cannot touch
    double reach2;  // its square
    // Ellipsoids: the axes divided by their semi-axes, and the squared "ratio" |local/half|² beyond
    // which dent + extra ≤ 0 (dist ≥ ratio·min semi-axis bounds the dent by −min·(ratio − 1)).
    glm::dvec3 scaledAxes[3];
    double ratio2Outside;
  };
  // The collision samples of one element: a grid u = first + j·CollisionStep, j < gridCount, and
  // the samples off that grid (the tip, when CollisionStep does not divide the length).
  struct ElementSamples {
    double first = 0.0;
    size_t gridCount = 0;
    std::vector<double> offGrid;
  };
  // The three sums of terms(): the elastic term itself, height (metres², × weight_ for gravity) and
  // penalty (× collisionStep_ for the collision term). With kKeepWalk, the walk up the rod is kept in
  // walkedElements_ and touchingSamples_ for valueAndGradient (a build of its own: the value alone pays
  // nothing for it).
  template <bool kKeepWalk>
  void accumulate(std::span<const double> q, double& elastic, double& height, double& penalty) const;
  // The penalty at p, and with `gradient` its gradient ∂/∂p there.
  double penalty(const glm::dvec3& p, glm::dvec3* gradient = nullptr) const;
  // Whether any point within `radius` of p may touch a shape (else its penalty is exactly 0).
  bool mayTouch(const glm::dvec3& p, double radius) const;

  std::vector<double> lengths_;
  RodFrame root_;
  RestShape rest_;
  double bend1_, bend2_, twist_;  // E I1 / 2, E I2 / 2, μ J / 2
  double weight_;                 // ρ S g, newtons per metre
  std::vector<Shape> shapes_;
  std::vector<ElementSamples> samples_;
  double collisionStep_;
  // valueAndGradient's walk: per element its start frame, end and displacement integral (world), and the
  // range of its samples that touch a shape; per such sample its arc length along the element, the
  // cos and sin of Ω u there, its position and the penalty's gradient there (Δs included).
  struct WalkedElement {
    RodFrame start;
    glm::dvec3 end, integral;
    double omega, cosLength, sinLength;  // Ω, and cos and sin of Ω ℓ (HelixElement's)
    size_t firstSample, endSample;
  };
  struct TouchingSample {
    double u, cosX, sinX;
    glm::dvec3 position, force;
  };
  mutable std::vector<WalkedElement> walkedElements_;
  mutable std::vector<TouchingSample> touchingSamples_;
};

}  // namespace hairgen
