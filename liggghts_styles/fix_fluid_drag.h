// fix fluid/drag: one-way coupled gas drag and buoyancy on granular spheres
// for LIGGGHTS 3.8. See docs/styles/fix_fluid_drag.md.
//
// The gas velocity and density come from the sampled field (field.h5, the
// uniform-grid format of postprocess/flow_field_io.h, read once when the fix
// is created) or from a uniform flow given on the fix line. The particles do
// not act back on the gas.
#ifndef MILL_FIX_FLUID_DRAG_H
#define MILL_FIX_FLUID_DRAG_H

#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "fix.h"

namespace mill::post {
struct FlowField;
}

namespace LAMMPS_NS {

class FixFluidDrag : public Fix {
 public:
  FixFluidDrag(class LAMMPS *lmp, int narg, char **arg);
  ~FixFluidDrag() override;

  static const char *style_name() { return "fluid/drag"; }

  // Drag coefficient of a sphere, Schiller & Naumann (1933) up to Re = 1000,
  // Newton's constant 0.424 above (method.md, stage 1). Re > 0.
  static double drag_coefficient(double re) {
    return re <= 1000.0 ? 24.0 / re * (1.0 + std::cbrt(re * re) / 6.0) : 0.424;
  }
  // C_d * Re, finite as Re -> 0 (24 in the Stokes limit); what the force uses.
  static double drag_coefficient_times_re(double re) {
    return re <= 1000.0 ? 24.0 * (1.0 + std::cbrt(re * re) / 6.0) : 0.424 * re;
  }

  int setmask() override;
  void init() override;
  void setup(int vflag) override;
  void post_force(int vflag) override;
  void post_run() override;
  double compute_vector(int n) override;

 private:
  double viscosity_ = 0.0;                    // mu, gas dynamic viscosity      [Pa s]
  bool uniform_ = false;                      // uniform flow instead of a file
  std::array<double, 3> u_uniform_{0, 0, 0};  // uniform gas velocity         [m/s]
  double rho_uniform_ = 0.0;                  // uniform gas density            [kg/m^3]
  std::array<double, 3> gravity_{0, 0, 0};    // g for buoyancy; 0 = none       [m/s^2]
  std::string field_path_;
  bool have_omega_ = false;  // `omega W`: the deck's rotor speed, checked
  double omega_ = 0.0;       //   against the field's rpm              [rad/s]
  std::unique_ptr<mill::post::FlowField> field_;

  // Cached once-per-step reductions (read by compute_vector).
  double masked_now_ = 0.0;     // particles without gas velocity this step
  double masked_total_ = 0.0;   // particle-steps without gas velocity this run
  double masked_max_ = 0.0;     // most particles without gas velocity at once
  double masked_warned_ = 0.0;  // masked_total_ at the last warning
  double re_max_ = 0.0;         // largest particle Reynolds number this step
  double dragged_now_ = 0.0;    // particles that felt drag this step

  void parse_args(int narg, char **arg);
  bool gas_at(const double *x, double *u, double &rho) const;
};

}  // namespace LAMMPS_NS

#endif
