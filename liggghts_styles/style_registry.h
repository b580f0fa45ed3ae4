// Registry of the project's LIGGGHTS styles.
//
// LIGGGHTS 3.8 keeps its fix-style table (Modify::fix_map) private and fills it
// from a compiled-in list. register_mill_styles() adds the project's styles to
// that table of a live LAMMPS instance, so that an input deck can use them by
// name. Call it after constructing LAMMPS and before input->file().
#ifndef MILL_STYLE_REGISTRY_H
#define MILL_STYLE_REGISTRY_H

#include <string>
#include <vector>

namespace LAMMPS_NS {
class LAMMPS;
}

namespace mill {

// Adds every project fix style to lmp's fix registry; returns their names.
std::vector<std::string> register_mill_styles(LAMMPS_NS::LAMMPS *lmp);

}  // namespace mill

#endif
