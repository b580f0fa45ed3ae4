// The case-file and ore-card schemas: the single place a key is declared.
#include "config/schema.h"

#include <fmt/format.h>

#include <array>
#include <sstream>

#include "lump/bond_parameters.h"

namespace mill::config {
namespace {

// Builders keep the table below readable: one line per key.
KeyDef key(std::string path, KeyType t, std::string unit, std::string def, std::string doc) {
  KeyDef k;
  k.path = std::move(path);
  k.type = t;
  k.unit = std::move(unit);
  k.default_yaml = std::move(def);
  k.doc = std::move(doc);
  return k;
}
KeyDef positive(KeyDef k) {
  k.min = 0.0;
  k.min_exclusive = true;
  return k;
}
KeyDef at_least(KeyDef k, double lo) {
  k.min = lo;
  return k;
}
KeyDef default_if(KeyDef k, std::string when, std::string is, std::string yaml) {
  k.default_if = DefaultIf{std::move(when), std::move(is), std::move(yaml)};
  return k;
}
KeyDef range(KeyDef k, double lo, bool lo_ex, double hi, bool hi_ex) {
  k.min = lo;
  k.min_exclusive = lo_ex;
  k.max = hi;
  k.max_exclusive = hi_ex;
  return k;
}
KeyDef choice(std::string path, std::string def, std::vector<std::string> choices,
              std::string doc) {
  KeyDef k = key(std::move(path), KeyType::Choice, "", std::move(def), std::move(doc));
  k.choices = std::move(choices);
  return k;
}
KeyDef opt(KeyDef k) {
  k.optional = true;
  return k;
}
// A bond parameter's key (`path`) with the unit, range and doc of its row
// in kBondParameters.
KeyDef bond_key(std::string path, const BondParameter& p, std::string def) {
  KeyDef k = key(std::move(path), KeyType::Real, p.unit, std::move(def), p.doc);
  k.min = p.range.min;
  k.min_exclusive = p.range.min_exclusive;
  if (p.range.max != kNoBound) k.max = p.range.max;
  k.max_exclusive = p.range.max_exclusive;
  return k;
}
KeyDef plausible(KeyDef k, double lo, double hi, std::string what, std::string source,
                 std::vector<UnitSlip> slips = {}) {
  k.plausible = Plausible{lo, hi, std::move(what), std::move(source), std::move(slips)};
  return k;
}
KeyDef matching(KeyDef k, std::string pattern, std::string text) {
  k.pattern = std::move(pattern);
  k.pattern_text = std::move(text);
  return k;
}

// Slurm resources of a stage's jobs on a cluster (`orchestrate hpc`): the
// values go into #SBATCH lines, so each is checked against Slurm's syntax.
const char* kSlurmTime = R"(\d+(:[0-5]\d){0,2}|\d+-\d{1,2}(:[0-5]\d){0,2})";
const char* kSlurmTimeText = "a Slurm wall time: MINUTES, MM:SS, HH:MM:SS or DAYS-HH[:MM[:SS]] (e.g. 02:00:00)";
const char* kSlurmMem = "[1-9][0-9]{0,8}[KMGT]?";
const char* kSlurmMemText = "a memory size: a whole number above 0, optional unit K, M, G or T (e.g. 4G; no unit: MB)";
const char* kSlurmName = "[A-Za-z0-9_.-]+(,[A-Za-z0-9_.-]+)*";
const char* kSlurmNameText = "a Slurm partition name (letters, digits, '_', '.', '-'; a comma between several)";

// The resources.<stage>.* keys of one stage (`orchestrate hpc`); `job` names
// one of its Slurm jobs in the docs. `np_default` "" = no ranks key (a stage
// without MPI), "-" = optional (the code falls back to --np or resources.np).
std::vector<KeyDef> stage_resources(const std::string& stage, const std::string& time, const std::string& np_default,
                                    const std::string& job) {
  const std::string p = "resources." + stage + ".";
  std::vector<KeyDef> v;
  if (np_default == "-")
    v.push_back(
        opt(at_least(key(p + "np", KeyType::Int, "", "",
                         "Cluster: MPI ranks per " + job +
                             "; default: --np, else resources.np. Set in the case file, also the "
                             "ranks of this stage's engine runs on this machine (--np overrides)"),
                     1)));
  else if (!np_default.empty())
    v.push_back(at_least(key(p + "np", KeyType::Int, "", np_default,
                             "Cluster: MPI ranks per " + job +
                                 " (--np overrides when the stage is scripted alone). Set in the "
                                 "case file, also the ranks of this stage's engine runs on this "
                                 "machine (--np overrides; unset there: resources.np)"),
                         1));
  v.push_back(matching(
      key(p + "time", KeyType::String, "", time, "Cluster: wall-time limit of each " + job + " (--time overrides)"),
      kSlurmTime, kSlurmTimeText));
  v.push_back(opt(matching(key(p + "mem", KeyType::String, "", "",
                               "Cluster: memory of each " + job + " (--mem overrides); default: the partition's"),
                           kSlurmMem, kSlurmMemText)));
  v.push_back(opt(matching(key(p + "partition", KeyType::String, "", "",
                               "Cluster: Slurm partition of the " + stage +
                                   " jobs (--partition overrides); default: the cluster's"),
                           kSlurmName, kSlurmNameText)));
  return v;
}

using T = KeyType;

// Units a value is often typed in instead of the key's SI unit.
const std::vector<UnitSlip> kPascalSlips = {{"kPa", 1e3}, {"MPa", 1e6}, {"GPa", 1e9}};
const std::vector<UnitSlip> kMetreSlips = {{"mm", 1e-3}, {"cm", 1e-2}};
constexpr double kPi = 3.14159265358979323846;

// Where the plausible ranges come from (docs/config.md, "Plausible ranges").
const char* kMillSource =
    "a mill as built, from laboratory rotor mills to industrial hammer mills and impact crushers "
    "(Wills & Finch 2016, Wills' Mineral Processing Technology, 8th ed., the chapter on crushers), with a margin of "
    "2-10 on each side";
const char* kRpmSource =
    "beater and hammer mills run at a few hundred to a few thousand rpm (Wills & Finch 2016, the "
    "chapter on crushers); the top end is held by the tip-speed bound of 300 m/s (docs/errors.md)";
const char* kAirSource = "properties of dry air and flue gases, VDI Heat Atlas (2nd ed., 2010)";
const char* kPlantPressureSource =
    "U.S. Standard Atmosphere (1976): 54 kPa at 5000 m altitude; a pressurised mill up to 5 bar";
const char* kPlantTemperatureSource =
    "plant conditions: cold ambient air (-70 degC) to the hot gas of a drying mill (about 600 degC)";
const char* kFeedSource = "the feed of impact crushers and hammer mills, a few mm to a few dm (Wills & Finch 2016, the chapter on crushers)";

const char* kSieveSource =
    "sieve sizes of a crusher's feed and product, from fines of a few um to feed lumps of a few dm (Wills & "
    "Finch 2016, the chapters on particle size analysis and on crushers), with a margin";
const char* kThroughputSource =
    "a mill's throughput, from laboratory rotor mills (a few kg/h) to the largest hammer mills and impact "
    "crushers (a few thousand t/h; Wills & Finch 2016, the chapter on crushers), with a margin";

const char* kRockDensitySource =
    "Schoen 2011, Physical Properties of Rocks: coal about 1300 kg/m^3, sandstone 2000-2700, basalt about "
    "3000, ore minerals up to galena's 7500";
const char* kRockModulusSource =
    "Goodman 1989, Introduction to Rock Mechanics (2nd ed.), ch. 6: intact rock from chalk and soft shale "
    "(about 1 GPa) to dense basalt and quartzite (about 100 GPa)";
const char* kPoissonSource = "Gercek 2007, Poisson's ratio values for rocks, Int. J. Rock Mech. Min. Sci. 44";
const char* kUcsSource =
    "Hoek & Brown 1997, Practical estimates of rock mass strength, field estimates of UCS: grade R1 "
    "(very weak, 1-5 MPa) to R6 (extremely strong, over 250 MPa); the strongest quartzites and basalts "
    "reach about 400 MPa";
const char* kTensileSource =
    "Goodman 1989, Introduction to Rock Mechanics (2nd ed.), ch. 3: rock's tensile strength is 1/25 to "
    "1/5 of its UCS (1-500 MPa, Hoek & Brown 1997)";
const char* kFrictionAngleSource =
    "typical values of intact rock in triaxial tests at low confinement, about 25 deg (shales, weak "
    "sandstones) to about 60 deg (strong crystalline rock), with a margin";
const char* kHoekBrownMiSource =
    "Hoek & Brown 1997, Practical estimates of rock mass strength, table of m_i for intact rock: from 4 +- 2 "
    "(claystones) to 32 +- 3 (granite), with a margin";
const char* kToughnessSource =
    "typical values of rock, about 0.1 MPa m^0.5 (weak sedimentary rock) to a few MPa m^0.5 (strong "
    "crystalline rock; Zhang 2002, Int. J. Rock Mech. Min. Sci. 39: sigma_t [MPa] ~ 6.88 K_IC "
    "[MPa m^0.5]), with a margin";
const char* kRockFrictionSource =
    "Byerlee 1978, Friction of rocks: 0.6-0.85 rock on rock; lower on steel and on polished surfaces";

// A length of the mill in metres, with its plausible range.
KeyDef mill_length(KeyDef k, double lo, double hi) {
  return plausible(std::move(k), lo, hi, "a mill as built", kMillSource, kMetreSlips);
}

// The case itself, the mill geometry and the rotor speeds.
std::vector<KeyDef> mill_keys() {
  return {
      key("name", T::String, "", "",
          "Case name, required: names the run folder runs/<name> (letters, digits, -, _, .; at most 100 "
          "characters)"),
      opt(key("description", T::String, "", "", "Free text shown in the report")),

      // --- mill geometry (shared by OpenFOAM and LIGGGHTS through STL) ---
      mill_length(positive(key("mill.housing.height", T::Real, "m", "4.0", "Housing height (y, vertical)")), 0.2, 20),
      mill_length(positive(key("mill.housing.width", T::Real, "m", "1.6", "Housing width (x)")), 0.2, 20),
      mill_length(positive(key("mill.housing.depth", T::Real, "m", "0.5", "Housing depth (z, along the rotor axis)")),
                  0.05, 10),
      mill_length(positive(key("mill.flywheel.diameter", T::Real, "m", "1.0", "Flywheel tip diameter (beater plate tips)")),
                  0.1, 5),
      mill_length(positive(key("mill.flywheel.hub_diameter", T::Real, "m", "0.3", "Hub (disc) diameter carrying the plates")),
                  0.02, 5),
      at_least(key("mill.flywheel.n_plates", T::Int, "", "6", "Number of flat beater plates"), 1),
      mill_length(positive(key("mill.flywheel.plate_width", T::Real, "m", "0.3", "Beater plate width along the axis")),
                  0.01, 5),
      mill_length(positive(key("mill.flywheel.plate_thickness", T::Real, "m", "0.02", "Beater plate thickness")), 0.002,
                  0.5),
      mill_length(positive(key("mill.flywheel.axis_height", T::Real, "m", "1.2",
                               "Height of the rotor axis above the housing floor")),
                  0.05, 20),
      mill_length(key("mill.flywheel.axis_x", T::Real, "m", "0.0", "Horizontal offset of the rotor axis from the housing centre"),
                  -10, 10),
      mill_length(key("mill.inlet.center_x", T::Real, "m", "0.0", "Inlet centre (x) on the housing roof"), -10, 10),
      mill_length(positive(key("mill.inlet.size", T::Real, "m", "0.3", "Inlet opening: side of a square on the roof")), 0.01,
                  10),
      mill_length(key("mill.outlet.center_x", T::Real, "m", "0.0", "Outlet centre (x) on the housing floor"), -10, 10),
      mill_length(positive(key("mill.outlet.size", T::Real, "m", "0.4", "Outlet opening: side of a square on the floor")),
                  0.01, 10),

      // --- rotor ---
      plausible(positive(key("rotor.rpm", T::RealList, "rpm", "[2000]", "Rotor speeds; one flow/transport run per speed")),
                300, 1e5, "a beater mill's rotor speed", kRpmSource, {{"rad/s", 60 / (2 * kPi)}, {"rev/s", 60}}),
      opt(key(kAllowOutsideRange, T::KeyList, "", "",
              "Keys of this case whose values may lie outside their plausible range (a deliberate outlier, e.g. "
              "[rotor.rpm]); recorded in resolved_case.json and the report"))};
}

// The gas, the CFD numerics (stage 1a) and the sampling of its field.
std::vector<KeyDef> flow_keys() {
  return {
      // --- gas ---
      choice("gas.model", "compressible", {"incompressible", "compressible"},
             "rhoSimpleFoam (air as a perfect gas, the method's model; its temperature carries no "
             "rotor work, see docs/flow.md \"Compressible gas\") or simpleFoam (constant density "
             "gas.density)"),
      plausible(positive(key("gas.density", T::Real, "kg/m^3", "1.2", "Gas density (incompressible model; reference for drag)")),
                0.1, 10, "a gas at plant conditions", kAirSource, {{"g/cm^3", 1e3}, {"g/m^3", 1e-3}}),
      plausible(positive(key("gas.viscosity", T::Real, "Pa s", "1.8e-5", "Gas dynamic viscosity")), 5e-6, 5e-5,
                "a gas at plant conditions", kAirSource, {{"mPa s", 1e-3}, {"uPa s", 1e-6}, {"P", 0.1}}),
      plausible(positive(key("gas.temperature", T::Real, "K", "293.15", "Gas temperature (compressible model)")), 200, 900,
                "a gas at plant conditions", kPlantTemperatureSource, {{"degC", 1, 273.15}}),
      plausible(positive(key("gas.pressure", T::Real, "Pa", "101325", "Absolute ambient pressure (compressible model)")),
                5e4, 5e5, "a plant's absolute gas pressure", kPlantPressureSource,
                {{"kPa", 1e3}, {"bar", 1e5}, {"atm", 101325}, {"MPa", 1e6}}),
      key("gas.outlet_pressure_drop", T::Real, "Pa", "0",
          "Outlet static pressure below inlet total pressure (below gas.pressure: the outlet stays above vacuum)"),

      // --- CFD numerics ---
      choice("flow.mesh_preset", "quick", {"tiny", "quick", "medium", "reference"},
             "tiny: a few thousand cells (tests); quick: tens of thousands (0.1 m background "
             "cells); medium: 0.07 m cells with boundary layers; reference: 0.05 m cells with "
             "boundary layers; all first-order momentum (flow.momentum_scheme); cell counts and "
             "the mesh study in docs/flow.md"),
      range(key("flow.rotor_angle", T::Real, "deg", "0",
                "Frozen-rotor position of the flywheel in the CFD (counter-clockwise about +z; 0: "
                "plate 0 along +x). The steady MRF solution depends on it; bench/README.md, "
                "\"Flow\", measures the spread over positions"),
            0, false, 360, true),
      choice("flow.momentum_scheme", "preset", {"preset", "upwind", "linearUpwind"},
             "Convection of momentum: preset = the mesh preset's (upwind on every preset); upwind "
             "= first order, converges on all presets; linearUpwind = second order (started with "
             "flow.first_order_iterations of upwind; does not converge on medium and reference: "
             "the plate wakes oscillate, docs/flow.md)"),
      at_least(key("flow.first_order_iterations", T::Int, "", "300",
                   "With second-order momentum (flow.momentum_scheme), first run this many "
                   "iterations with first-order upwind, then switch (the solver restarts from that "
                   "state); 0: second order from the start"),
               0),
      at_least(key("flow.max_iterations", T::Int, "", "600", "Iteration cap of the steady solver"),
               1),
      positive(key("flow.residual_target", T::Real, "", "1e-4",
                   "Initial-residual target for p and U (convergence)")),
      key("flow.allow_unconverged", T::Bool, "", "false",
          "Go on with a flow that missed flow.residual_target within flow.max_iterations (sample, "
          "transport and what follows run on it; the report says so at the top). false: the sample "
          "and transport stages stop with an error naming the run"),
      choice("flow.domain", "half", {"half", "full"},
             "half: solve z >= 0 with a symmetry plane at z = 0 and mirror it (the mill is "
             "mirror-symmetric; the full-domain steady solve is carried away by an antisymmetric "
             "mode, see docs/flow.md); full: the whole housing"),

      // --- sampling of the flow field ---
      positive(
          key("sample.spacing", T::Real, "m", "0.05", "Spacing of the uniform 3D sampling grid")),
      key("sample.turbulence", T::Bool, "", "false", "Also sample k and omega")};
}

// The ore injection and the lumps' transport (stage 1b), and the ore card.
std::vector<KeyDef> transport_keys() {
  return {// --- ore injection (stage 1 transport) ---
          range(key("injection.n_lumps", T::Int, "", "360", "Number of ore lumps injected (with a feed: of each lump size, injection.lump_diameter's and each fed class's; at most 1e5: a plan limit)"), 1,
                false, 1e5, false),
          plausible(positive(key("injection.lump_diameter", T::Real, "m", "0.04", "Lump diameter")), 0.002, 0.5,
                    "a beater mill's feed", kFeedSource, kMetreSlips),
          positive(key("injection.duration", T::Real, "s", "0.2",
                       "Lumps are inserted evenly over this time (with a feed, the m lump sizes take turns at the inlet: each over m times this)")),
          positive(
              key("injection.time_limit", T::Real, "s", "2.0", "Transport run stops at this time (with a feed, it must outlast m x injection.duration)")),
          positive(key("injection.timestep", T::Real, "s", "5e-6", "Particle time step")),
          at_least(key("injection.seed", T::Int, "", "4711", "Random seed of the insertion"), 1),
          positive(key("transport.trajectory_interval", T::Real, "s", "2e-3",
                       "Trajectory sampling interval (transport.h5, plot)")),
          at_least(key("transport.vtk_interval", T::Real, "s", "0.01",
                       "VTK dump interval of lumps and meshes (ParaView); 0 = none"),
                   0),
          positive(
              key("transport.sliding_threshold", T::Real, "m/s", "1.0",
                  "Contacts whose normal speed relative to the surface is below this are sliding "
                  "(touch-downs, rolling, chatter): counted apart (summary.json sliding_contacts), "
                  "left out of the impact statistics and of the beater strikes")),

          // --- ore ---
          key("ore.card", T::Path, "", "liggghts_inputs/materials/sandstone.yaml",
              "Ore card (YAML); relative to the case file, else to the project")};
}

// The bonded lump (stage 2 and the calibration's specimens).
std::vector<KeyDef> lump_keys() {
  return {// --- bonded lump model (stage 2) ---
          range(key("lump.n_elements", T::Int, "", "3344", "Elements (spheres) per lump"), kMinLumpElements, false, 1e7, false),
          plausible(positive(key("lump.diameter", T::Real, "m", "0.04", "Lump diameter")), 0.002, 0.5,
                    "a beater mill's feed", kFeedSource, kMetreSlips),
          range(key("lump.radius_spread", T::Real, "", "0.25",
                    "Element radii uniform in (1 +- spread) x mean"),
                0, false, 1, true),
          at_least(key("lump.n_packings", T::Int, "", "1",
                       "Distinct random packings (lumps) for statistics"),
                   1),
          at_least(key("lump.seed", T::Int, "", "1001", "Seed of the first packing"), 1),
          at_least(key("lump.bond_gap", T::Real, "", "0.15",
                       "Bond pairs whose gap is below this x min(Ri, Rj) (0.15: coordination ~6.3 "
                       "at 3344 elements)"),
                   0),
          range(key("lump.max_bonds", T::Int, "", "16",
                    "Cap of bonds per element (at most 64, the limit of fix bond/breakable)"),
                1, false, 64, false),
          bond_key("lump.bond_radius_multiplier", bond_parameter("radius_multiplier"), "1.0"),
          key("lump.broken_contact", T::Bool, "", "false",
              "Parallel bond: broken bonds stay as compression-only frictional contacts while the pair is "
              "within its bonding range (fix bond/breakable broken_contact)"),
          choice("lump.bond_model", "parallel", {"parallel", "flat_joint"},
                 "The bonded contact: parallel (a cement disc that breaks whole, fix bond/breakable; Potyondy & "
                 "Cundall 2004) or flat_joint (an interface of elements that break one by one and stay as "
                 "frictional contacts, fix bond/flatjoint; Potyondy 2012); docs/calibration.md"),
          range(key("lump.joint_rings", T::Int, "", "1", "Flat joint: rings of elements per interface"), 1, false,
                kMaxJointElements, false),
          range(key("lump.joint_sectors", T::Int, "", "3",
                    "Flat joint: sectors of elements per interface (at least 3: the intact interface then has the "
                    "disc's area and moments)"),
                3, false, kMaxJointElements, false),
          opt(at_least(key("lump.joint_friction", T::Real, "", "",
                           "Flat joint: friction coefficient of its broken elements (Potyondy 2012's mu; fix "
                           "bond/flatjoint joint_friction); absent: tan of the bond friction angle. Part of the "
                           "lump's scale a calibration holds for (bench/README.md, \"UCS/T of 10 at bond gap 1.4\")"),
                       0))};
}

// The breakage stage: its sweep or transport conditions, and the in-mill runs.
std::vector<KeyDef> breakage_keys() {
  return {
      // --- breakage sweep (stage 2) ---
      choice("breakage.conditions", "sweep", {"sweep", "transport"},
             "sweep: the velocities/angles below; transport: binned from stage 1 impacts"),
      range(key("breakage.velocities", T::RealList, "m/s",
                "[4, 10, 20, 40, 60, 80, 100, 120, 150, 169]",
                "Impact speeds of the sweep (beater mills reach 50-150 m/s; above 500 m/s a "
                "rock lump is a shock "
                "problem the bond model does not describe)"),
            0, true, 500, false),
      range(key("breakage.angles", T::RealList, "deg", "[90]",
                "Impact angles to the surface (90 = normal)"),
            0, true, 90, false),
      at_least(
          key("breakage.repeats", T::Int, "", "1", "Repeats per condition (random orientation)"),
          1),
      opt(range(key("breakage.crossing_velocities", T::RealList, "m/s", "",
                    "sweep conditions: speeds of breakage.velocities run "
                    "breakage.crossing_repeats times instead of breakage.repeats: those where "
                    "the largest piece crosses breakage.critical_largest_fraction. There the "
                    "curve is flat and one repeat moves the critical speed by several m/s "
                    "(docs/breakage.md, \"Repeats at the crossing\"); the per-repeat spreads "
                    "read the repeats every speed has; absent = none"),
                0, true, 500, false)),
      at_least(key("breakage.crossing_repeats", T::Int, "", "6",
                   "Repeats of each speed in breakage.crossing_velocities (at least "
                   "breakage.repeats)"),
               1),
      positive(key("breakage.duration_after_contact", T::Real, "s", "6e-3",
                   "Simulated time after first contact, at most")),
      at_least(key("breakage.quiet_time", T::Real, "s", "1e-3",
                   "Stop earlier once no bond broke for this long after contact; 0 = always "
                   "the full duration"),
               0),
      at_least(key("breakage.timestep", T::Real, "s", "0",
                   "Time step; 0 = automatic from the stability limit"),
               0),
      key("breakage.adaptive_step", T::Bool, "", "true",
          "With the automatic time step (breakage.timestep: 0), re-evaluate it at the end of "
          "each 0.25 ms chunk of an impact or in-mill run from the bonds left: half the "
          "critical step of the remaining bonds, at most the contacts' and the speed's bound "
          "and twice the step before (fix step/adaptive, docs/styles/fix_step_adaptive.md). "
          "The step grows once the lump has shattered; bench/README.md, \"Adaptive time "
          "step\", measures what it gains and that the results agree with the fixed step's "
          "within the repeats' spread; false = one step for the whole run (so is a given "
          "breakage.timestep)"),
      at_least(key("breakage.dump_interval", T::Real, "s", "5e-4",
                   "VTK dump interval in simulated time (with breakage.adaptive_step the "
                   "dumps stay at it as the step changes); 0 = no dumps"),
               0),
      range(key("breakage.size_fraction_edges", T::RealList, "",
                "[0, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.85, 1.0]",
                "Edges of the size fractions, piece diameter / lump diameter (ascending)"),
            0, false, 1, false),
      range(key("breakage.critical_largest_fraction", T::Real, "", "0.05",
                "Critical velocity: largest piece mass fraction falls below this"),
            0, true, 1, true),
      at_least(key("breakage.velocity_bins", T::Int, "", "5",
                   "transport conditions: bins of impact normal speed"),
               1),
      key("breakage.include_wall_impacts", T::Bool, "", "false",
          "transport conditions: also wall impacts"),
      opt(range(key("breakage.strength_velocities", T::RealList, "m/s", "",
                    "transport conditions: normal single impacts at these speeds beside stage "
                    "1's, breakage.repeats each, that measure the lump's strength where the "
                    "mill's impacts do not reach (below them): the critical impact speed and "
                    "the JK fit read them with the mill's impacts, the mill's product does "
                    "not (docs/breakage.md, \"Strength impacts\"); absent = none"),
                0, true, 500, false)),
      default_if(
          at_least(key("breakage.in_mill.lumps", T::Int, "", "0",
                       "In-mill breakage (needs conditions: transport): lumps per rotor speed "
                       "(and feed class) run as bonded lumps in the turning mill from stage 1's "
                       "first flywheel strikes, chosen spread over the strike speeds; 0 = none. "
                       "The default 4 gives the product and the decision a band (a bootstrap "
                       "over the lumps; bench/README.md, \"Feed to product\")"),
                   0),
          "breakage.conditions", "transport", "4"),
      positive(key("breakage.in_mill.duration", T::Real, "s", "0.02",
                   "In-mill breakage: simulated time of each run, from lead_time before the "
                   "strike (long enough for "
                   "the fragments' first housing impacts)")),
      positive(key("breakage.in_mill.lead_time", T::Real, "s", "2e-3",
                   "In-mill breakage: a run starts this long before the lump's first flywheel "
                   "strike (its state "
                   "backed off ballistically from the strike)")),
      key("breakage.in_mill.gas", T::Bool, "", "true",
          "In-mill breakage: gas drag on each element from the sampled field (sample stage); "
          "false = no gas"),
      key("breakage.in_mill.early_stop", T::Bool, "", "true",
          "In-mill breakage: end a run before duration, at the end of a 0.25 ms chunk, once "
          "the strike is over: an element has touched the flywheel or the housing, no "
          "element is within the tip radius plus one lump diameter of the axis (nor gets "
          "there within a chunk at its speed towards the axis), and every element whose "
          "latest flywheel contact came after its latest housing contact has left the "
          "housing (docs/breakage.md); false = every run lasts duration"),
      key("breakage.in_mill.skip_free_flight", T::Bool, "", "true",
          "In-mill breakage: start the engine run where the lump's free flight ends, not "
          "lead_time before the strike: until an element touches a surface the lump moves as "
          "one rigid body along the ballistic path its start was backed off along, so the "
          "run starts once its bounding sphere is within half its radius of the housing or "
          "the turning flywheel (the skipped time is in_mill.json's "
          "start.free_flight_skipped_s; docs/breakage.md); false = the whole lead time is "
          "simulated"),
      key("breakage.in_mill.animate", T::Bool, "", "true",
          "In-mill breakage: the first in-mill run (the first lump of the first rotor speed) "
          "also writes 60 frames over duration, drawn as an animation in the report "
          "(breakage/animation/, docs/report.md); false = none (that run keeps the job id "
          "it had without the frames)"),
      at_least(key("breakage.in_mill.neighbour_bins", T::Int, "", "500000",
                   "In-mill breakage: most neighbour bins over the simulation box, which holds "
                   "the whole mill "
                   "(LIGGGHTS clears every bin at each list build and walks every bin of "
                   "each turning flywheel facet's box); the bins start at the "
                   "larger of 4 mean element "
                   "radii and (box volume / this)^(1/3) and grow as the fragments spread "
                   "(bench/README.md, \"In-mill neighbour bins\": 500 000 costs 15-28 % "
                   "less than 4 000 000 for lumps of 200-1700 elements, 23 % over the "
                   "3344-element reference lump's 20 ms)"),
               1000)};
}

// A size of the feed or the product in mm, with its plausible range.
KeyDef sieve_mm(KeyDef k) {
  return plausible(positive(std::move(k)), 1e-3, 1000, "a sieve size of a crusher's feed or product", kSieveSource,
                   {{"m", 1e3}, {"um", 1e-3}});
}

// The feed of the mill and its cut: the population balance's inputs
// (docs/population_balance.md). Optional as a whole: a case without any
// feed.* key runs one lump size. No key has a default, so a case without a
// feed keeps its job ids and inputs hash.
std::vector<KeyDef> feed_keys() {
  return {
      opt(sieve_mm(key("feed.sizes_mm", T::RealList, "mm", "",
                       "Feed: the sieves of the population balance, ascending; each is the upper edge of a size "
                       "class (pieces that pass it and stay on the sieve below; the finest class runs down to 0). "
                       "List the product's fine sieves too, with fraction 0: the product P80 is read off them. "
                       "Required with a feed"))),
      opt(plausible(range(key("feed.mass_fractions", T::RealList, "", "",
                              "Feed: mass fraction of each class of feed.sizes_mm (as many), summing to 1 within 1e-6 "
                              "(then scaled to sum to 1 exactly); or feed.rosin_rammler instead"),
                          0, false, 1, false),
                    0, 1, "a mass fraction", "a mass fraction lies in [0, 1]", {{"%", 0.01}})),
      opt(sieve_mm(key("feed.rosin_rammler.d63_mm", T::Real, "mm", "",
                       "Feed: Rosin-Rammler size through which 63.2 % of the mass passes, F(d) = 1 - "
                       "exp(-(d/d63)^n) (Rosin & Rammler 1933), put on the classes of feed.sizes_mm (the top class "
                       "also takes the tail above the top sieve, at most 1 %); instead of feed.mass_fractions"))),
      opt(positive(key("feed.rosin_rammler.n", T::Real, "", "",
                       "Feed: Rosin-Rammler uniformity n; give with feed.rosin_rammler.d63_mm"))),
      opt(plausible(positive(key("feed.rate_tph", T::Real, "t/h", "", "Feed: fresh feed rate. Required with a feed")),
                    1e-3, 1e4, "a mill's throughput", kThroughputSource, {{"kg/h", 1e-3}, {"kg/s", 3.6}})),
      opt(sieve_mm(key("feed.cut_size_mm", T::Real, "mm", "",
                       "Feed: the mill's cut, the aperture of its outlet grate or classifier: pieces above it go "
                       "round again, those below leave (a class across it splits in log size); at or above the "
                       "finest sieve. Required with a feed"))),
      opt(sieve_mm(key("feed.target_p80_mm", T::Real, "mm", "",
                       "Feed: the product P80 wanted (optional); at or above the finest sieve and below "
                       "feed.cut_size_mm"))),
      opt(range(key("feed.class_element_cap", T::Int, "", "",
                    "Feed: most elements of a class's in-mill lump, as a multiple of lump.n_elements; absent = "
                    "no cap. A class lump has the calibration's element size, so its count follows its "
                    "diameter (a class of twice lump.diameter: about 8 x); a cap saves time on coarse classes "
                    "but gives them coarser elements, and a shattered lump's product is mostly single "
                    "elements, so their product is coarser in proportion (bench/README.md, \"A class lump "
                    "at the element cap\": elements 1.53 x the calibration's gave a 6.82 mm P80 against 4.36 mm)"),
                1, false, 1000, false))};
}

// The calibration's virtual lab tests.
std::vector<KeyDef> calibrate_keys() {
  return {
      // --- calibration (virtual lab tests) ---
      range(key("calibrate.n_elements", T::Int, "", "1500", "Elements in a lab specimen"), 20,
            false, 1e7, false),
      positive(key("calibrate.strain_rate", T::Real, "1/s", "0.5",
                   "Platen strain rate of the UCS and Brazilian tests")),
      at_least(key("calibrate.max_iterations", T::Int, "", "8", "Calibration iterations cap"), 1),
      positive(key("calibrate.tolerance", T::Real, "", "0.1",
                   "Relative tolerance on E, UCS and tensile strength")),
      at_least(key("calibrate.seed", T::Int, "", "2002", "Seed of the specimen packing"), 1),
      range(key("calibrate.starts", T::Int, "", "1",
                "Fits from different starts: 1 fits from the closed-form estimate; N > 1 adds N - "
                "1 fits "
                "from that estimate scaled within x/÷ 2 (Halton points), each a parameter set of "
                "its own "
                "(calibrate/sets.json), and the breakage stage repeats its impacts with every set "
                "to give the "
                "band of critical impact speeds the ore card leaves open (docs/calibration.md, "
                "\"Parameter "
                "sets from different starts\"). Each start costs a fit; each set, the sweep's "
                "impacts again"),
            1, false, 8, false),
      key("calibrate.fit_toughness", T::Bool, "", "true",
          "With flat joints (lump.bond_model: flat_joint) and an ore card that gives "
          "fracture_toughness: "
          "every iteration also runs the semi-circular bend test and the fit aims at K_IC as a "
          "fifth target "
          "(its lever: the bond tensile strength against the cohesion). false: K_IC is a check "
          "after the "
          "fit only, as it always is for the parallel bond (docs/calibration.md, \"The toughness "
          "as a "
          "target\")"),
      range(key("calibrate.scb_orientations", T::Int, "", "6",
                "With an ore card that gives fracture_toughness: half discs per semi-circular bend "
                "test, each "
                "carved from the specimen ball turned a further 180 deg / N about the load axis; "
                "K_IC is their "
                "mean, reported with its standard error and range. One half disc of a few hundred "
                "elements "
                "scatters K_IC by tens of per cent with where its notch cuts the packing "
                "(docs/calibration.md, "
                "\"The toughness as a target\"). Each half disc costs a few seconds per bend test"),
            1, false, 12, false),
      choice("calibrate.tensile_test", "brazilian", {"brazilian", "direct"},
             "The virtual test the fit aims the tensile strength at: brazilian (the ore card's "
             "tensile_strength, a Brazilian disc) or direct (a direct tension test: the UCS "
             "cylinder pulled "
             "apart by its end layers, aimed at the card's direct_tensile_strength, else at its "
             "Brazilian "
             "strength x f of its rock_class, DTS = f BTS with f 0.7 sedimentary, 0.8 igneous, 0.9 "
             "metamorphic, Perras & Diederichs 2014). A bonded packing's Brazilian disc can fail "
             "by shear "
             "and crushing under the jaws instead of a tensile split (flat joints: "
             "docs/calibration.md, "
             "\"The direct tension test\"); the Brazilian test still runs and is reported"),
      key("calibrate.rate_check", T::Bool, "", "true",
          "After the fit, repeat the UCS test at half the strain rate (quasi-static check)"),
      range(key("calibrate.fit_packings", T::Int, "", "1",
                "Specimen packings each iteration of the fit tests, each carved from its own ball "
                "(the seed "
                "streams after calibrate.seed's): the fit aims the means of E, nu, UCS and the "
                "tensile strength "
                "over them at the ore card, as a lab reads several specimens. A specimen of a few "
                "hundred "
                "elements spreads by tens of per cent from packing to packing "
                "(calibrate.packing_check); the mean "
                "of N spreads about 1/sqrt(N) as much (docs/calibration.md, \"Fitting the mean of "
                "several "
                "packings\"). Each packing costs the iteration's UCS and Brazilian tests again; "
                "the rate check, "
                "sensitivities and checks stay on the first packing"),
            1, false, 8, false),
      range(key("calibrate.packing_check", T::Int, "", "2",
                "After the fit, repeat the result's UCS and Brazilian tests on this many further "
                "specimen "
                "packings (the seed streams after calibrate.seed's) and report how far E, nu, UCS "
                "and the tensile "
                "strength spread between the packings (the fit's own packings included); beyond "
                "the fit's tolerance it "
                "warns that the "
                "specimens are too small (docs/calibration.md, \"Packing check\"). 0: no check"),
            0, false, 8, false),
      key("calibrate.sensitivity", T::Bool, "", "true",
          "After the fit, step each fitted bond parameter alone from the result (x1.2; friction "
          "angle +5 deg; "
          "moment factor -0.25) in one UCS + Brazilian pair each and report each lever's "
          "sensitivity (the "
          "change in each target per change in the lever) and which levers move no target "
          "(docs/calibration.md, "
          "\"Lever sensitivities\")"),
      range(key("calibrate.confining_pressures", T::RealList, "x ucs", "[0.1, 0.2]",
                "After the fit, one triaxial test per entry at this confining pressure (a fraction "
                "of the UCS "
                "the result reached: the card's ucs when met) with the result's bond parameters: "
                "the failure "
                "envelope, a check, not fitted. At most 1/4: above it the virtual test leaves the "
                "Mohr-Coulomb "
                "line (docs/calibration.md)"),
            0, true, 0.25, false)};
}

// The resources of the engine runs, here and per stage on a cluster.
std::vector<KeyDef> resources_keys() {
  std::vector<KeyDef> v = {
      // --- resources ---
      range(key("resources.np", T::Int, "", "1", "MPI ranks per engine run (--np overrides)"), 1, false, 1e5, false),
      range(key("resources.jobs", T::Int, "", "1", "Engine runs at once on this machine (--jobs overrides)"), 1, false,
            1024, false),
      matching(key("resources.merge.time", T::String, "", "00:20:00",
                   "Cluster: wall-time limit of the small jobs between stages (merges, planning)"),
               kSlurmTime, kSlurmTimeText)};
  // Per stage on a cluster: the flow wants ranks, breakage many one-rank tasks.
  for (const auto& [stage, time, np, what] : std::vector<std::array<std::string, 4>>{
           {"flow", "04:00:00", "-", "flow task (one per rotor speed)"},
           {"sample", "00:30:00", "", "sample job"},
           {"transport", "02:00:00", "1", "transport task (one per rotor speed)"},
           {"calibrate", "02:00:00", "1", "calibration job"},
           {"breakage", "01:00:00", "1", "breakage task (one per impact condition)"},
           {"report", "00:30:00", "", "report job"}})
    for (auto& k : stage_resources(stage, time, np, what)) v.push_back(std::move(k));
  return v;
}

Schema make_case_schema() {
  Schema s;
  s.what = "case file";
  for (const auto& part : {mill_keys(), flow_keys(), transport_keys(), lump_keys(), breakage_keys(), feed_keys(),
                           calibrate_keys(), resources_keys()})
    s.keys.insert(s.keys.end(), part.begin(), part.end());
  return s;
}

Schema make_ore_schema() {
  Schema s;
  s.what = "ore card";
  s.keys = {
      key("name", T::String, "", "", "Ore name"),
      opt(key("source", T::String, "", "", "Where the values come from (citation)")),
      plausible(positive(key("density", T::Real, "kg/m^3", "", "Bulk density")), 1000, 8000,
                "a rock's density", kRockDensitySource, {{"g/cm^3", 1e3}}),
      plausible(positive(key("youngs_modulus", T::Real, "Pa", "", "Young's modulus E")), 5e8, 2e11,
                "a rock's Young's modulus", kRockModulusSource, kPascalSlips),
      plausible(
          range(key("poisson_ratio", T::Real, "", "", "Poisson's ratio nu"), 0, false, 0.5, true),
          0.01, 0.45, "a rock's Poisson's ratio", kPoissonSource, {{"%", 0.01}}),
      plausible(positive(key("ucs", T::Real, "Pa", "", "Uniaxial compressive strength")), 1e6, 5e8,
                "a rock's uniaxial compressive strength", kUcsSource, kPascalSlips),
      plausible(
          positive(key("tensile_strength", T::Real, "Pa", "", "Tensile strength (Brazilian)")), 1e5,
          5e7, "a rock's tensile strength", kTensileSource, kPascalSlips),
      plausible(at_least(key("friction", T::Real, "", "0.5",
                             "Coulomb friction coefficient (element-element and walls)"),
                         0),
                0.05, 1.5, "a rock's friction coefficient", kRockFrictionSource),
      range(key("restitution", T::Real, "", "0.5", "Coefficient of restitution"), 0, true, 1,
            false),
      // The rock's failure envelope and toughness, optional: the calibration
      // checks its result against them (docs/calibration.md, "Checks after
      // the fit"); they change no simulation and no fitted parameter.
      opt(plausible(range(key("friction_angle", T::Real, "deg", "",
                              "Internal friction angle phi of the intact rock (Mohr-Coulomb, from "
                              "triaxial tests "
                              "over the calibration's confinement, calibrate.confining_pressures); "
                              "the calibration "
                              "reports its envelope against it (a check, not fitted)"),
                          0, true, 90, true),
                    10, 70, "a rock's internal friction angle", kFrictionAngleSource)),
      opt(plausible(
          positive(
              key("hoek_brown_mi", T::Real, "", "",
                  "Hoek-Brown constant m_i of the intact rock (Hoek & Brown 1997); the calibration "
                  "reports its envelope's m_i against it (a check, not fitted)")),
          1, 50, "a rock's Hoek-Brown m_i", kHoekBrownMiSource)),
      opt(plausible(
          positive(key(
              "fracture_toughness", T::Real, "Pa m^0.5", "",
              "Mode-I fracture toughness K_IC; given, the calibration runs a semi-circular bend "
              "test (Kuruppu et al. 2014) and reports its K_IC against it; with flat joints it is "
              "also a "
              "target of the fit (calibrate.fit_toughness), with the parallel bond a check only")),
          2e4, 1e7, "a rock's mode-I fracture toughness", kToughnessSource,
          {{"kPa m^0.5", 1e3}, {"MPa m^0.5", 1e6}})),
      // The tensile strength in direct tension, optional: the target of a fit
      // with calibrate.tensile_test direct (docs/calibration.md, "The direct
      // tension test"); the card's tensile_strength is the Brazilian one.
      opt(choice(
          "rock_class", "", {"sedimentary", "igneous", "metamorphic"},
          "The rock's origin, for the direct tensile strength when the card gives none: DTS = f x "
          "tensile_strength with f 0.7 (sedimentary), 0.8 (igneous) or 0.9 (metamorphic) (Perras & "
          "Diederichs 2014, Geotech. Geol. Eng. 32); read only with calibrate.tensile_test "
          "direct")),
      opt(plausible(
          positive(
              key("direct_tensile_strength", T::Real, "Pa", "",
                  "Tensile strength in direct (uniaxial) tension, when the lab measured it; the "
                  "target of a fit with calibrate.tensile_test direct (else rock_class converts "
                  "tensile_strength)")),
          1e5, 5e7, "a rock's tensile strength", kTensileSource, kPascalSlips)),
      // Measured JK drop-weight parameters (Napier-Munn et al. 1996), optional:
      // drawn against the breakage sweep's own fit; they change no simulation.
      opt(range(key("jk.A", T::Real, "%", "",
                    "Measured JK breakage parameter A: the largest t10 of the ore (drop-weight "
                    "test); give with jk.b"),
                0, true, 100, false)),
      opt(range(key("jk.b", T::Real, "t/kWh", "",
                    "Measured JK breakage parameter b (t10 = A (1 - exp(-b Ecs)), Ecs in kWh/t); "
                    "give with jk.A"),
                0, true, 100, false)),
      opt(key("jk.source", T::String, "", "",
              "Where the measured A and b come from (laboratory, report)")),
      opt(key(kAllowOutsideRange, T::KeyList, "", "",
              "Keys of this card whose values may lie outside their plausible range (a deliberate "
              "outlier, e.g. "
              "[ucs]); recorded in resolved_case.json and the report")),
  };
  // Calibrated micro parameters (written by `--stage calibrate`, optional):
  // one key per fitted row of kBondParameters, and the hash they were fitted to.
  const std::string cal = std::string(kCalibratedSection) + ".";
  s.keys.push_back(opt(choice(cal + kModelKey, "", {"parallel", "flat_joint"},
                              "Bond model the calibration was made with (absent: parallel; lump.bond_model)")));
  s.keys.push_back(opt(range(key(cal + kRingsKey, T::Int, "", "", "Flat joint: rings of elements (lump.joint_rings)"),
                             1, false, kMaxJointElements, false)));
  s.keys.push_back(opt(range(key(cal + kSectorsKey, T::Int, "", "", "Flat joint: sectors of elements (lump.joint_sectors)"),
                             3, false, kMaxJointElements, false)));
  for (const BondParameter& p : kBondParameters)
    if (p.calibrated)
      s.keys.push_back(opt(bond_key(cal + p.calibrated, p, "")));
  s.keys.push_back(opt(key(std::string(kCalibratedSection) + "." + kInputHashKey, T::String, "", "",
                           "Hash of what these were fitted to: the card's macro properties (and K_IC when a "
                           "target), the lump's element size and bonding range")));
  // The lump scale they were fitted for (lump/material.h, lump_scale): it
  // names what differs when the section does not apply to a case.
  const std::string ff = cal + kFittedForKey + ".";
  s.keys.push_back(opt(positive(key(ff + "element_radius_m", T::Real, "m", "",
                                    "Mean element radius the calibration was fitted at (from lump.n_elements, "
                                    "lump.diameter, lump.radius_spread)"))));
  s.keys.push_back(opt(key(ff + "radius_spread", T::Real, "", "", "lump.radius_spread of that fit")));
  s.keys.push_back(opt(key(ff + "bond_gap", T::Real, "", "", "lump.bond_gap of that fit")));
  s.keys.push_back(opt(key(ff + "bond_radius_multiplier", T::Real, "", "", "lump.bond_radius_multiplier of that fit")));
  s.keys.push_back(opt(key(ff + "broken_contact", T::Bool, "", "", "lump.broken_contact of that fit (parallel bond)")));
  s.keys.push_back(opt(key(ff + "joint_friction", T::Real, "", "", "lump.joint_friction of that fit (flat joint; absent: not set)")));
  return s;
}

}  // namespace

const KeyDef* Schema::find(const std::string& path) const {
  for (const auto& k : keys)
    if (k.path == path) return &k;
  return nullptr;
}

bool Schema::is_section(const std::string& path) const {
  const std::string prefix = path + ".";
  for (const auto& k : keys)
    if (k.path.compare(0, prefix.size(), prefix) == 0) return true;
  return false;
}

const Schema& case_schema() {
  static const Schema s = make_case_schema();
  return s;
}

const Schema& ore_schema() {
  static const Schema s = make_ore_schema();
  return s;
}

std::string type_name(KeyType t) {
  switch (t) {
    case KeyType::Int: return "integer";
    case KeyType::Real: return "number";
    case KeyType::Bool: return "true/false";
    case KeyType::String: return "text";
    case KeyType::Choice: return "choice";
    case KeyType::Path: return "file path";
    case KeyType::RealList: return "list of numbers";
    case KeyType::IntList: return "list of integers";
    case KeyType::KeyList: return "list of key names";
  }
  return "?";
}

std::string num(double v) {
  std::string t = fmt::format("{:.6g}", v);
  const size_t e = t.find('e');
  if (e == std::string::npos) return t;
  std::string exp = t.substr(e + 1);
  const bool negative = exp[0] == '-';
  exp.erase(0, exp.find_first_not_of("+-0"));
  return t.substr(0, e) + "e" + (negative ? "-" : "") + exp;
}

std::string slip_hint(const KeyDef& k, double v) {
  if (!k.plausible) return "";
  std::string hint;
  for (const UnitSlip& s : k.plausible->slips) {
    const double si = v * s.factor + s.offset;
    if (si >= k.plausible->lo && si <= k.plausible->hi)
      hint += fmt::format("{}{} {} ({}{})", hint.empty() ? "" : " or ", num(v), s.unit, num(si),
                          k.unit.empty() ? "" : " " + k.unit);
  }
  return hint;
}

std::string expected_text(const KeyDef& k) {
  if (!k.pattern_text.empty()) return k.pattern_text;
  if (k.type == KeyType::KeyList) return "a list of keys of this file that have a plausible range";
  if (k.type == KeyType::Choice) {
    std::string s = "one of ";
    for (size_t i = 0; i < k.choices.size(); ++i) s += (i ? ", " : "") + k.choices[i];
    return s;
  }
  std::string unit = k.unit.empty() ? "" : " " + k.unit;
  // Whole-number bounds in full (10000000), others as num() writes them (5e8).
  const auto bound = [&](double b) {
    return k.type == KeyType::Int || k.type == KeyType::IntList ? fmt::format("{}", static_cast<long long>(b)) : num(b);
  };
  if (k.min && k.max)
    return fmt::format("{} in {}{}, {}{}{}", type_name(k.type), k.min_exclusive ? "(" : "[", bound(*k.min),
                       bound(*k.max), k.max_exclusive ? ")" : "]", unit);
  if (k.min) return fmt::format("{} {} {}{}", type_name(k.type), k.min_exclusive ? ">" : ">=", bound(*k.min), unit);
  if (k.max) return fmt::format("{} {} {}{}", type_name(k.type), k.max_exclusive ? "<" : "<=", bound(*k.max), unit);
  return type_name(k.type) + (unit.empty() ? "" : " (" + k.unit + ")");
}

namespace {
void table(std::ostringstream& o, const Schema& s) {
  o << "| key | type | unit | default | allowed | description |\n";
  o << "|---|---|---|---|---|---|\n";
  for (const auto& k : s.keys) {
    std::string def = k.default_yaml.empty() ? (k.optional ? "(optional)" : "(required)") : "`" + k.default_yaml + "`";
    if (k.default_if)
      def = "`" + k.default_if->yaml + "` with `" + k.default_if->when + ": " + k.default_if->is + "`, else " + def;
    o << "| `" << k.path << "` | " << type_name(k.type) << " | " << (k.unit.empty() ? "-" : k.unit) << " | "
      << def << " | " << expected_text(k) << " | " << k.doc << " |\n";
  }
}
// The plausible ranges of a schema, with their sources and the unit slips named.
void plausible_table(std::ostringstream& o, const Schema& s) {
  o << "| key | plausible | unit slips named | source |\n";
  o << "|---|---|---|---|\n";
  for (const auto& k : s.keys) {
    if (!k.plausible) continue;
    std::string slips;
    for (const auto& u : k.plausible->slips) slips += (slips.empty() ? "" : ", ") + u.unit;
    o << "| `" << k.path << "` | " << num(k.plausible->lo) << " to " << num(k.plausible->hi)
      << (k.unit.empty() ? "" : " " + k.unit) << " (" << k.plausible->what << ") | " << (slips.empty() ? "-" : slips)
      << " | " << k.plausible->source << " |\n";
  }
}
}  // namespace

std::string schema_markdown() {
  std::ostringstream o;
  o << "# Configuration reference\n\n"
    << "Generated by `orchestrate --print-schema`; do not edit by hand.\n"
    << "All quantities are SI unless the unit column says otherwise. A key that is absent\n"
    << "takes its default; an unknown key is an error.\n\n"
    << "## Case file (`cases/*.yaml`)\n\n";
  table(o, case_schema());
  o << "\nThe `feed.*` keys are optional as a whole: without any, a case runs one lump size. With a feed,\n"
    << "`feed.sizes_mm`, `feed.rate_tph`, `feed.cut_size_mm` and exactly one distribution (`feed.mass_fractions`\n"
    << "or `feed.rosin_rammler`) are required; the rules and an example are in docs/population_balance.md,\n"
    << "\"The feed in the case\".\n";
  o << "\n## Ore card (`liggghts_inputs/materials/*.yaml`)\n\n";
  table(o, ore_schema());
  o << "\n## Plausible ranges\n\n"
    << "A physical key of the case or the ore card also has a plausible range: the values a real rock, gas or\n"
    << "mill takes. A value outside it is an error that names the file, the key, the value and the unit it was\n"
    << "likely typed in (`ucs: 50 Pa: did you mean 50 MPa (5e7 Pa)?`). A deliberate outlier is allowed by\n"
    << "listing its key in `" << kAllowOutsideRange << "` of the same file (the case for case keys, the ore card\n"
    << "for card keys), e.g. `" << kAllowOutsideRange << ": [ucs]`; the list is kept in resolved_case.json and\n"
    << "shown at the top of the report. The hard bounds of the tables above hold even then.\n\n"
    << "### Case file\n\n";
  plausible_table(o, case_schema());
  o << "\n### Ore card\n\n";
  plausible_table(o, ore_schema());
  return o.str();
}

}  // namespace mill::config
