// Stage 'sample': the flow solution on a uniform grid (HDF5, VTI, PNG).
#include "stages/sample_stage.h"

#include <fmt/format.h>
#include <unistd.h>
#include <vtkCompositeDataSet.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkOpenFOAMReader.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkResampleToImage.h>
#include <vtkSMPTools.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>

#include <array>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "geometry/mill_geometry.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "progress.h"
#include "stages/flow_stage.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;

namespace sample {
namespace {

constexpr double kAirGasConstant =
    8314.462618 / 28.96;  // J/(kg K), as in the case's perfectGas (molWeight 28.96)

template <typename T>
using Ptr = vtkSmartPointer<T>;

// True for a half-domain case of the flow stage (flow.domain = half): the
// mesh is z >= 0 with the symmetryPlane patch `symmetry` at z = 0.
bool half_domain_case(const fs::path& case_dir) {
  std::ifstream in(case_dir / "constant" / "polyMesh" / "boundary");
  std::stringstream ss;
  ss << in.rdbuf();
  static const std::regex re("\\bsymmetry\\s*\\{[^}]*\\btype\\s+symmetryPlane\\s*;");
  return std::regex_search(ss.str(), re);
}

// The probed upper planes of a grid of nz planes symmetric about z = 0
// (planes nz/2 .. nz-1, z >= 0) reflected onto the whole grid: U_x, U_y,
// rho, mask (k, omega) even in z, U_z odd.
post::FlowField mirror_z(const post::FlowField& upper, int nz) {
  post::FlowField f = upper;
  const int k0 = nz / 2;
  if (upper.dims[2] != nz - k0)
    throw std::invalid_argument(
        fmt::format("mirror_z: {} probed planes do not make a grid of {}", upper.dims[2], nz));
  f.dims[2] = nz;
  f.origin[2] = upper.origin[2] - k0 * upper.spacing[2];
  f.allocate(!upper.k.empty());
  const size_t plane = static_cast<size_t>(f.dims[0]) * f.dims[1];
  for (int k = 0; k < nz; ++k) {
    const bool reflected = k < k0;
    const int ks = (reflected ? nz - 1 - k : k) - k0;  // plane of `upper`
    const size_t dst = k * plane, src = ks * plane;
    for (size_t q = 0; q < plane; ++q) {
      f.mask[dst + q] = upper.mask[src + q];
      f.rho[dst + q] = upper.rho[src + q];
      for (int c = 0; c < 3; ++c) {
        const double u = upper.U[3 * (src + q) + c];
        f.U[3 * (dst + q) + c] = (reflected && c == 2 && u != 0.0) ? -u : u;
      }
      if (!upper.k.empty()) {
        f.k[dst + q] = upper.k[src + q];
        f.omega[dst + q] = upper.omega[src + q];
      }
    }
  }
  return f;
}

// Copy one VTK point array (nc components) into dst, zero where mask = 0.
void take(vtkDataArray* a, int nc, const std::vector<std::uint8_t>& mask,
          std::vector<double>& dst) {
  const vtkIdType n = static_cast<vtkIdType>(mask.size());
  for (vtkIdType i = 0; i < n; ++i)
    for (int c = 0; c < nc; ++c) dst[nc * i + c] = mask[i] ? a->GetComponent(i, c) : 0.0;
}

}  // namespace

// Grid of exact spacing centred in the box.
post::FlowField make_grid(const GridSpec& g) {
  post::FlowField f;
  for (int d = 0; d < 3; ++d) {
    const double L = g.hi[d] - g.lo[d];
    const int n = std::max(2, static_cast<int>(std::floor(L / g.spacing + 1e-9)) + 1);
    f.dims[d] = n;
    f.spacing[d] = g.spacing;
    f.origin[d] = g.lo[d] + 0.5 * (L - (n - 1) * g.spacing);
  }
  return f;
}

namespace {

// The case's reader on its internal mesh with the cell fields the sampler
// needs (U; rho, or p and T, unless the density is constant; k and omega with
// opt.turbulence) and `t`, its latest time. Throws naming a missing field.
Ptr<vtkOpenFOAMReader> open_case(const fs::path& case_dir, const Options& opt, double& t) {
  const fs::path foam = case_dir / "case.foam";
  if (!fs::exists(case_dir / "constant" / "polyMesh"))
    throw std::runtime_error(
        fmt::format("{}: no mesh (constant/polyMesh) to sample", case_dir.string()));
  if (!fs::exists(foam)) std::ofstream(foam).close();

  auto reader = Ptr<vtkOpenFOAMReader>::New();
  reader->SetFileName(foam.c_str());
  reader->SetSkipZeroTime(true);  // 0/ holds the template fields (with $macros), never a result
  reader->SetCreateCellToPoint(1);
  // Keep snappyHexMesh's split-hex cells as polyhedra: decomposed, points on
  // refinement-level interfaces fall between the pieces and come out masked.
  reader->SetDecomposePolyhedra(0);
  reader->UpdateInformation();
  reader->DisableAllPatchArrays();
  reader->SetPatchArrayStatus("internalMesh", 1);
  reader->DisableAllLagrangianArrays();
  reader->DisableAllPointArrays();
  reader->DisableAllCellArrays();
  auto has_cell_array = [&](const char* name) {
    for (int i = 0; i < reader->GetNumberOfCellArrays(); ++i)
      if (std::string(reader->GetCellArrayName(i)) == name) return true;
    return false;
  };
  std::vector<std::string> want{"U"};
  if (opt.constant_rho <= 0) {
    if (has_cell_array("rho"))
      want.push_back("rho");
    else
      want.insert(want.end(), {"p", "T"});
  }
  if (opt.turbulence) want.insert(want.end(), {"k", "omega"});
  for (const auto& w : want) {
    if (!has_cell_array(w.c_str()))
      throw std::runtime_error(fmt::format(
          "{}: field '{}' not found in the latest time folder (has the flow stage finished?)",
          case_dir.string(), w));
    reader->SetCellArrayStatus(w.c_str(), 1);
  }
  vtkDoubleArray* times = reader->GetTimeValues();
  t = (times && times->GetNumberOfTuples() > 0) ? times->GetValue(times->GetNumberOfTuples() - 1)
                                                : 0.0;
  return reader;
}

// The grid planes a case is probed on. Half-domain case (flow.domain = half):
// the mesh covers z >= 0 only, so the planes k >= k0 of the grid are probed
// (z >= 0; the grid is symmetric about z = 0 because the box is) and the
// planes k < k0 filled by reflection afterwards.
struct ProbedPlanes {
  post::FlowField full;  // the whole grid
  post::FlowField f;     // the probed planes k0 .. nz-1
  bool mirror = false;
  bool on_plane = false;  // grid plane k0 lies on the symmetry plane z = 0
};

ProbedPlanes probed_planes(const fs::path& case_dir, const GridSpec& grid) {
  ProbedPlanes p;
  p.full = make_grid(grid);
  p.mirror = half_domain_case(case_dir);
  int k0 = 0;
  if (p.mirror) {
    const double L = grid.hi[2] - grid.lo[2];
    if (std::abs(grid.lo[2] + grid.hi[2]) > 1e-9 * L)
      throw std::invalid_argument(fmt::format(
          "{}: a half-domain case is mirrored about z = 0, but the sampling box z {:g} .. {:g} "
          "is not symmetric about it",
          case_dir.string(), grid.lo[2], grid.hi[2]));
    k0 = p.full.dims[2] / 2;  // odd nz: the plane z = 0; even nz: the first plane z > 0
    p.on_plane = p.full.dims[2] % 2 == 1;
  }
  p.f = p.full;
  p.f.dims[2] = p.full.dims[2] - k0;
  p.f.origin[2] = p.full.origin[2] + k0 * p.full.spacing[2];
  return p;
}

// The box the resampler probes, slightly inside the nominal one: points
// exactly on the housing walls would otherwise fall in or out of the mesh by
// round-off, and snapping moves wall points by a fraction of a millimetre
// (see grid.wall_inset).
std::array<double, 6> sampling_bounds(const ProbedPlanes& p, const GridSpec& grid) {
  const post::FlowField& f = p.f;
  std::array<double, 6> b{};
  for (int d = 0; d < 3; ++d) {
    const double e = std::max(1e-6 * f.spacing[d], grid.wall_inset);
    b[2 * d] = f.origin[d] + e;
    b[2 * d + 1] = f.origin[d] + (f.dims[d] - 1) * f.spacing[d] - e;
  }
  if (p.mirror) {
    // The symmetry plane is a mesh boundary like the walls: probe the grid
    // plane lying on it just inside the half mesh; other planes as usual.
    const double e = std::max(1e-6 * f.spacing[2], grid.wall_inset);
    b[4] = f.origin[2] + (p.on_plane ? e : 0.0);
    if (f.dims[2] == 1) b[4] = b[5];
  }
  return b;
}

// The resampled point data into f: the mask, U, the density (constant, the
// case's rho, or p / (R T)) and, with opt.turbulence, k and omega.
void take_fields(post::FlowField& f, vtkPointData* pd, const char* mask_name, const Options& opt,
                 const fs::path& case_dir) {
  f.allocate(opt.turbulence);
  vtkDataArray* valid = pd->GetArray(mask_name);
  vtkDataArray* U = pd->GetArray("U");
  if (!valid || !U)
    throw std::runtime_error(
        fmt::format("{}: resampled grid lacks U or the mask", case_dir.string()));
  for (size_t i = 0; i < f.size(); ++i) f.mask[i] = valid->GetComponent(i, 0) > 0.5 ? 1 : 0;
  take(U, 3, f.mask, f.U);
  if (opt.constant_rho > 0) {
    for (size_t i = 0; i < f.size(); ++i) f.rho[i] = f.mask[i] ? opt.constant_rho : 0.0;
  } else if (vtkDataArray* r = pd->GetArray("rho")) {
    take(r, 1, f.mask, f.rho);
  } else {
    vtkDataArray *p = pd->GetArray("p"), *T = pd->GetArray("T");
    for (size_t i = 0; i < f.size(); ++i)
      f.rho[i] =
          f.mask[i] ? p->GetComponent(i, 0) / (kAirGasConstant * T->GetComponent(i, 0)) : 0.0;
  }
  if (opt.turbulence) {
    take(pd->GetArray("k"), 1, f.mask, f.k);
    take(pd->GetArray("omega"), 1, f.mask, f.omega);
  }
}

}  // namespace

// vtkOpenFOAMReader -> vtkResampleToImage -> FlowField.
post::FlowField resample_case(const fs::path& case_dir, const GridSpec& grid, const Options& opt) {
  double t = 0;
  const auto reader = open_case(case_dir, opt, t);
  ProbedPlanes p = probed_planes(case_dir, grid);
  post::FlowField& f = p.f;
  // Probe on one thread: with VTK's threaded backend each thread keeps its own
  // cell-search hint, so a grid point on a face shared by two cells took the
  // value of either cell depending on thread timing (runs differed by up to
  // 0.4 m/s on the tiny mesh, and the transport stage amplified it).
  vtkSMPTools::SetBackend("Sequential");
  auto rs = Ptr<vtkResampleToImage>::New();
  rs->SetInputConnection(reader->GetOutputPort());
  rs->SetUseInputBounds(false);
  std::array<double, 6> b = sampling_bounds(p, grid);
  rs->SetSamplingBounds(b.data());
  rs->SetSamplingDimensions(f.dims[0], f.dims[1], f.dims[2]);
  rs->UpdateTimeStep(t);
  vtkImageData* img = rs->GetOutput();
  if (!img || img->GetNumberOfPoints() != static_cast<vtkIdType>(f.size()))
    throw std::runtime_error(fmt::format("{}: resampling produced no grid", case_dir.string()));
  take_fields(f, img->GetPointData(), rs->GetMaskArrayName(), opt, case_dir);
  f.source =
      fmt::format("{} (time {:g}), vtkOpenFOAMReader + vtkResampleToImage", case_dir.string(), t);
  if (!p.mirror) return std::move(f);
  if (p.on_plane)  // the symmetry plane's condition: no flow through it
    for (int j = 0; j < f.dims[1]; ++j)
      for (int i = 0; i < f.dims[0]; ++i) f.U[3 * f.point(i, j, 0) + 2] = 0.0;
  return mirror_z(f, p.full.dims[2]);
}

// FlowField -> vtkImageData -> XML (.vti, binary appended, compressed).
void write_vti(const fs::path& file, const post::FlowField& f) {
  auto img = Ptr<vtkImageData>::New();
  img->SetDimensions(f.dims[0], f.dims[1], f.dims[2]);
  img->SetOrigin(f.origin[0], f.origin[1], f.origin[2]);
  img->SetSpacing(f.spacing[0], f.spacing[1], f.spacing[2]);
  const vtkIdType n = static_cast<vtkIdType>(f.size());
  auto add = [&](const char* name, int nc, const std::vector<double>& v) {
    if (v.empty()) return;
    auto a = Ptr<vtkDoubleArray>::New();
    a->SetName(name);
    a->SetNumberOfComponents(nc);
    a->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n * nc; ++i) a->SetValue(i, v[i]);
    img->GetPointData()->AddArray(a);
  };
  add("U", 3, f.U);
  add("rho", 1, f.rho);
  add("k", 1, f.k);
  add("omega", 1, f.omega);
  auto m = Ptr<vtkUnsignedCharArray>::New();
  m->SetName("mask");
  m->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i) m->SetValue(i, f.mask[i]);
  img->GetPointData()->AddArray(m);
  img->GetPointData()->SetActiveVectors("U");

  auto w = Ptr<vtkXMLImageDataWriter>::New();
  w->SetFileName(file.c_str());
  w->SetInputData(img);
  w->SetDataModeToAppended();
  if (!w->Write()) throw std::runtime_error("cannot write " + file.string());
}

// |U| on the plane k nearest to z, bilinear, upscaled to ~800 px high.
std::array<double, 2> write_midplane_png(const fs::path& file, const post::FlowField& f, double z) {
  const int nx = f.dims[0], ny = f.dims[1];
  const int k =
      std::clamp(static_cast<int>(std::lround((z - f.origin[2]) / f.spacing[2])), 0, f.dims[2] - 1);
  std::vector<double> speed(static_cast<size_t>(nx) * ny);
  double vmax = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const size_t p = f.point(i, j, k);
      const double s = std::sqrt(f.U[3 * p] * f.U[3 * p] + f.U[3 * p + 1] * f.U[3 * p + 1] +
                                 f.U[3 * p + 2] * f.U[3 * p + 2]);
      speed[static_cast<size_t>(j) * nx + i] = f.mask[p] ? s : NAN;
      if (f.mask[p]) vmax = std::max(vmax, s);
    }
  if (vmax <= 0) vmax = 1;

  auto lut = Ptr<vtkLookupTable>::New();
  lut->SetHueRange(0.667, 0.0);  // blue (slow) -> red (fast)
  lut->SetTableRange(0, vmax);
  lut->SetNanColor(0.6, 0.6, 0.6, 1.0);
  lut->Build();

  const int scale = std::max(1, 800 / std::max(ny - 1, 1));
  const int W = (nx - 1) * scale + 1, H = (ny - 1) * scale + 1, bar = std::max(12, W / 12), gap = 6;
  auto img = Ptr<vtkImageData>::New();
  img->SetDimensions(W + gap + bar, H, 1);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto put = [&](int x, int y, const unsigned char* rgb) {
    auto* px = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
    px[0] = rgb[0], px[1] = rgb[1], px[2] = rgb[2];
  };
  const unsigned char white[3] = {255, 255, 255};
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const double fx = static_cast<double>(x) / scale, fy = static_cast<double>(y) / scale;
      const int i = std::min(static_cast<int>(fx), nx - 2),
                j = std::min(static_cast<int>(fy), ny - 2);
      const double wx = fx - i, wy = fy - j;
      const double v00 = speed[j * nx + i], v10 = speed[j * nx + i + 1],
                   v01 = speed[(j + 1) * nx + i], v11 = speed[(j + 1) * nx + i + 1];
      double v;
      if (std::isnan(v00) || std::isnan(v10) || std::isnan(v01) ||
          std::isnan(v11))  // nearest near solids
        v = speed[static_cast<size_t>(std::lround(fy)) * nx + std::lround(fx)];
      else
        v = (1 - wx) * (1 - wy) * v00 + wx * (1 - wy) * v10 + (1 - wx) * wy * v01 + wx * wy * v11;
      put(x, y, lut->MapValue(v));  // image y grows upwards in VTK: the floor is at the bottom
    }
    for (int x = W; x < W + gap; ++x) put(x, y, white);
    for (int x = W + gap; x < W + gap + bar; ++x)
      put(x, y, lut->MapValue(vmax * y / std::max(H - 1, 1)));
  }
  auto w = Ptr<vtkPNGWriter>::New();
  w->SetFileName(file.c_str());
  w->SetInputData(img);
  w->Write();
  if (!fs::exists(file)) throw std::runtime_error("cannot write " + file.string());
  return {0.0, vmax};
}

}  // namespace sample

// One job per rotor speed, matching the flow stage's jobs.
Plan SampleStage::plan(const StageContext& ctx) const {
  Plan p;
  for (double rpm : ctx.cfg.doc.reals("rotor.rpm")) {
    nlohmann::json in = case_keys(ctx.cfg.doc, {"mill.", "gas.", "flow.", "sample."});
    in["rotor.rpm"] = rpm;
    p.jobs.push_back({rpm_label(rpm), in, "sample flow/" + rpm_label(rpm) + " on a uniform grid"});
  }
  return p;
}

// sample/<label>/{field.h5, field.vti, midplane_speed.png, sample_report.json}.
std::string SampleStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  const fs::path out = ctx.stage_dir / job.label;
  return jobs::first_problem(
      {jobs::check_json(out / "sample_report.json"), jobs::check_hdf5(out / "field.h5"),
       jobs::check_file(out / "field.vti"), jobs::check_file(out / "midplane_speed.png")});
}

// flow/<label>/case -> sample/<label>/{field.h5, field.vti, midplane_speed.png}.
void SampleStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path&) {
  const auto& doc = ctx.cfg.doc;
  const fs::path flow_out = flow::output_dir(ctx.run_dir, job.label);
  if (!fs::exists(flow_out / "flow_report.json"))
    throw MissingInput(
        fmt::format("stage sample needs {} (the flow solution at {}); run --stage flow first",
                    (flow_out / "flow_report.json").string(), job.label));
  const auto geo = geometry::MillGeometry::from_config(doc);
  sample::GridSpec grid;
  grid.lo = {-0.5 * geo.width, 0.0, -0.5 * geo.depth};
  grid.hi = {0.5 * geo.width, geo.height, 0.5 * geo.depth};
  grid.spacing = doc.real("sample.spacing");
  const double min_side = std::min({geo.width, geo.height, geo.depth});
  grid.wall_inset = 2e-3 * min_side;
  // sample.spacing <= min_side / 2: checked with the case (config/case_config.cpp).
  sample::Options opt;
  opt.turbulence = doc.boolean("sample.turbulence");
  // Which part of the housing the flow stage solved: its report and its mesh
  // (resample_case mirrors a mesh with the `symmetry` plane) must agree.
  std::ifstream rep_in(flow_out / "flow_report.json");
  const auto flow_rep = nlohmann::json::parse(rep_in, nullptr, false);
  const std::string domain =
      flow_rep.is_object() ? flow_rep.value("domain", std::string("full")) : "full";
  const double job_rpm = job.inputs.at("rotor.rpm").get<double>();
  if (flow_rep.is_object() && flow_rep.contains("rpm") && flow_rep["rpm"].is_number() &&
      flow_rep["rpm"].get<double>() != job_rpm)
    throw std::runtime_error(fmt::format(
        "{}: the flow was solved at {:g} rpm, not the {:g} rpm of this job; rerun --stage flow",
        (flow_out / "flow_report.json").string(), flow_rep["rpm"].get<double>(), job_rpm));
  // An unconverged flow is not a prediction: stop here unless the case says
  // to go on (the report then says so at the top).
  if (flow_rep.is_object() && flow_rep.value("converged", true) == false &&
      !doc.boolean("flow.allow_unconverged")) {
    const auto res = flow_rep.value("final_initial_residuals", nlohmann::json::object());
    std::string r;
    for (const auto& [k, v] : res.items())
      if (v.is_number()) r += fmt::format("{}{} {:.2g}", r.empty() ? "" : ", ", k, v.get<double>());
    throw std::runtime_error(fmt::format(
        "flow/{} did not converge: initial residuals {} after {} iterations, target {:g} "
        "(flow.residual_target); its gas field is not a prediction. Raise flow.max_iterations, "
        "choose another flow.mesh_preset, or set flow.allow_unconverged: true in {} to go on "
        "with it (the report then says so at the top); solver log in {}",
        job.label, r.empty() ? "?" : r, flow_rep.value("iterations", 0),
        flow_rep.value("residual_target", 0.0), doc.file(), (flow_out / "case").string()));
  }
  const bool mirrored = sample::half_domain_case(flow_out / "case");
  if (mirrored != (domain == "half"))
    throw std::runtime_error(fmt::format(
        "{}: flow_report.json says domain '{}' but the mesh {} the symmetry plane of a half "
        "domain; rerun --stage flow",
        flow_out.string(), domain, mirrored ? "has" : "lacks"));
  const bool comp = doc.str("gas.model") == "compressible";
  if (!comp) opt.constant_rho = doc.real("gas.density");

  ctx.progress.job_step(job.label, "resample", -1);
  post::FlowField f = sample::resample_case(flow_out / "case", grid, opt);
  f.rpm = job_rpm;
  f.gas_model = doc.str("gas.model");
  f.source = "flow/" + job.label + "/case, vtkOpenFOAMReader + vtkResampleToImage" +
             (mirrored ? ", half domain z >= 0 mirrored about z = 0 (Uz flipped)" : "");

  size_t gas = 0;
  double umax = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    gas += f.mask[i];
    umax = std::max(umax, std::hypot(f.U[3 * i], f.U[3 * i + 1], f.U[3 * i + 2]));
  }
  if (gas == 0)
    throw std::runtime_error(
        fmt::format("no grid point fell inside the gas mesh of {}", (flow_out / "case").string()));

  const fs::path out = ctx.stage_dir / job.label;
  const fs::path tmp = out.string() + ".tmp." + std::to_string(getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  post::write_flow_field(tmp / "field.h5", f);
  sample::write_vti(tmp / "field.vti", f);
  const auto range = sample::write_midplane_png(tmp / "midplane_speed.png", f, 0.0);
  nlohmann::json rep = {
      {"rpm", f.rpm},
      {"dims", f.dims},
      {"origin_m", f.origin},
      {"spacing_m", f.spacing},
      {"points", f.size()},
      {"gas_points", gas},
      {"gas_fraction", static_cast<double>(gas) / f.size()},
      {"max_speed_m_s", umax},
      {"flow_domain", domain},
      {"flow_converged", flow_rep.is_object() ? flow_rep.value("converged", true) : true},
      {"mirrored_about_z0", mirrored},
      {"midplane_png",
       {{"file", "midplane_speed.png"},
        {"z_m", 0.0},
        {"speed_range_m_s", range},
        {"colours", "blue (0) to red (max); grey = solid; bar on the right"}}},
      {"files", {"field.h5", "field.vti", "midplane_speed.png"}}};
  jobs::atomic_write(tmp / "sample_report.json", rep.dump(2) + "\n");
  fs::remove_all(out);
  fs::rename(tmp, out);
  ctx.progress.info(fmt::format(
      "sample/{}: {}x{}x{} grid at {:g} m, {:.1f}% in the gas, max |U| {:.1f} m/s -> {}", job.label,
      f.dims[0], f.dims[1], f.dims[2], grid.spacing, 100.0 * gas / f.size(), umax, out.string()));
}

}  // namespace mill
