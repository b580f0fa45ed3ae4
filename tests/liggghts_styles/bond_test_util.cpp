#include "bond_test_util.h"

#include <fstream>
#include <sstream>

namespace mill_test {

double sphere_mass(double r) { return kRho * 4.0 / 3.0 * kPi * r * r * r; }
double sphere_inertia(double r) { return 0.4 * sphere_mass(r) * r * r; }

std::string bond_fix(const std::string &extra, double sigma_t, double cohesion) {
  std::ostringstream s;
  s.precision(17);
  s << "fix bonds all bond/breakable radius_multiplier 1.0 modulus " << kEb << " stiffness_ratio "
    << kRatio << " tensile_strength " << sigma_t << " cohesion " << cohesion << " friction_angle "
    << kPhiDeg << " damping 0.0 gap " << kGap << " max_bonds 16 " << extra << "\n";
  return s.str();
}

std::string flat_joint_fix(const std::string &extra, double sigma_t, double cohesion, int rings,
                           int sectors) {
  std::ostringstream s;
  s.precision(17);
  s << "fix bonds all bond/flatjoint radius_multiplier 1.0 modulus " << kEb << " stiffness_ratio "
    << kRatio << " tensile_strength " << sigma_t << " cohesion " << cohesion << " friction_angle "
    << kPhiDeg << " gap " << kGap << " max_bonds 16 elements " << rings << " " << sectors << " "
    << extra << "\n";
  return s.str();
}

std::string head_split_x(double half_box) {
  std::string head = deck_head(half_box);
  const std::string comm_line = "communicate single vel yes\n";
  head.insert(head.find(comm_line) + comm_line.size(), "processors * 1 1\n");
  return head;
}

std::string head_data(double half_box, bool split_x) {
  std::string head = split_x ? head_split_x(half_box) : deck_head(half_box);
  const size_t a = head.find("region box block");
  const std::string create = "create_box 1 box\n";
  const size_t b = head.find(create);
  head.replace(a, b + create.size() - a, "read_data data.txt\n");
  return head;
}

std::string data_text(const std::vector<Sphere> &atoms, double half_box) {
  std::ostringstream d;
  d.precision(17);
  d << "LIGGGHTS data file (bond tests)\n\n"
    << atoms.size() << " atoms\n1 atom types\n\n"
    << -half_box << " " << half_box << " xlo xhi\n"
    << -half_box << " " << half_box << " ylo yhi\n"
    << -half_box << " " << half_box << " zlo zhi\n\nAtoms\n\n";
  for (size_t k = 0; k < atoms.size(); ++k)
    d << k + 1 << " 1 " << 2.0 * atoms[k].r << " " << kRho << " " << atoms[k].x[0] << " "
      << atoms[k].x[1] << " " << atoms[k].x[2] << "\n";
  d << "\nVelocities\n\n";
  for (size_t k = 0; k < atoms.size(); ++k)
    d << k + 1 << " " << atoms[k].v[0] << " " << atoms[k].v[1] << " " << atoms[k].v[2] << " "
      << atoms[k].w[0] << " " << atoms[k].w[1] << " " << atoms[k].w[2] << "\n";
  return d.str();
}

RunResult run_with_data(const std::string &dir, const std::vector<Sphere> &atoms,
                        const std::string &body, double half_box, int nprocs, bool split_x) {
  {
    std::ofstream out(dir + "/data.txt");
    out << data_text(atoms, half_box);
  }
  return run_deck(dir, head_data(half_box, split_x) + body, nprocs);
}

std::vector<Sphere> spinning_pair(const std::array<double, 3> &wa,
                                  const std::array<double, 3> &wb) {
  Sphere a, b;
  b.x = {kL0, 0.0, 0.0};
  a.w = wa;
  b.w = wb;
  return {a, b};
}

std::vector<std::vector<double>> last_run_rows(const std::string &path) {
  std::vector<std::vector<double>> rows;
  for (auto &row : read_table(path)) {
    while (!rows.empty() && rows.back()[0] >= row[0]) rows.pop_back();
    rows.push_back(row);
  }
  return rows;
}

std::vector<double> crossings_up(const std::vector<std::vector<double>> &rows, int col,
                                 double level) {
  std::vector<double> t;
  for (size_t k = 1; k < rows.size(); ++k) {
    const double y0 = rows[k - 1][col] - level, y1 = rows[k][col] - level;
    if (y0 < 0.0 && y1 >= 0.0)
      t.push_back(rows[k - 1][0] + (rows[k][0] - rows[k - 1][0]) * (-y0) / (y1 - y0));
  }
  return t;
}

std::string bonded_ball_head(double half_xy, double z_top) {
  std::ostringstream d;
  d.precision(17);
  d << "units si\natom_style sphere\natom_modify map array\nboundary f f f\nnewton off\n"
    << "communicate single vel yes\nprocessors * 1 1\n"
    << "region box block " << -half_xy << " " << half_xy << " " << -half_xy << " " << half_xy
    << " -0.002 " << z_top << " units box\ncreate_box 1 box\n"
    << "neighbor 0.0003 bin\nneigh_modify delay 0\nhard_particles yes\n"
    << "fix m1 all property/global youngsModulus peratomtype 5e9\n"
    << "fix m2 all property/global poissonsRatio peratomtype 0.25\n"
    << "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n"
    << "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n"
    << "pair_style gran model hertz tangential history\npair_coeff * *\n"
    << "lattice sc " << kL0 << "\n"
    << "region ball sphere 0 0 0.0105 " << 4.2 * kL0 << " units box\n"
    << "create_atoms 1 region ball\n"
    << "set group all diameter " << 2 * kR << " density " << kRho << "\n";
  return d.str();
}

// Final positions (id -> xyz) from a `dump custom id x y z` file.
std::map<int, std::array<double, 3>> read_positions(const std::string &path) {
  std::map<int, std::array<double, 3>> pos;
  std::ifstream in(path);
  std::string line;
  bool atoms = false;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms = true;
      pos.clear();
      continue;
    }
    if (line.rfind("ITEM:", 0) == 0) {
      atoms = false;
      continue;
    }
    if (!atoms) continue;
    std::istringstream ls(line);
    int id;
    double x, y, z;
    if (ls >> id >> x >> y >> z) pos[id] = {x, y, z};
  }
  return pos;
}

}  // namespace mill_test
