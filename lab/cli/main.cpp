// The `rocklab` command.

#include <CLI/CLI.hpp>
#include <functional>
#include <iostream>
#include <sstream>

#include "lab/cli/bench.hpp"
#include "lab/cli/build_info.hpp"
#include "lab/cli/lab_commands.hpp"
#include "lab/cli/study_commands.hpp"
#include "lab/core/contact_laws.hpp"
#include "lab/core/packing_io.hpp"
#include "reports/report.hpp"

namespace {

std::string versionLine() {
  std::ostringstream s;
  s << "rocklab " << rocklab::kVersion << " (git " << rocklab::kGitRevision << ", "
    << rocklab::kBuildType << " build" << (*rocklab::kBuildFlags ? ", " : "")
    << rocklab::kBuildFlags << ")";
  return s.str();
}

int runBenchCommand(rocklab::BenchOptions o, bool json) {
  using namespace rocklab;
  Packing<3> packing;
  std::string source;
  if (!o.packing.empty()) {
    if (packingFileDimension(o.packing) != 3) {
      throw std::runtime_error(o.packing + ": the benchmark scene is 3D; this packing is 2D");
    }
    packing = readPacking<3>(o.packing);
    source = o.packing;
  } else {
    if (!json)
      std::cerr << "generating a packing of " << o.n << " spheres (seed " << o.seed
                << ") at 1 MPa ...\n";
    packing = benchPacking(o.n, o.seed, o.threads.front());
    source = "generated (N = " + std::to_string(o.n) + ", seed " + std::to_string(o.seed) + ")";
    if (!o.save_packing.empty()) {
      writePacking<3>(o.save_packing, packing,
                      "rocklab bench packing, radii uniform [0.9, 1.1] mm, 1 MPa, seed " +
                          std::to_string(o.seed));
    }
  }
  if (o.tile != std::array<int, 3>{1, 1, 1}) {
    packing = tilePacking(packing, o.tile);
    source += " tiled " + std::to_string(o.tile[0]) + "x" + std::to_string(o.tile[1]) + "x" +
              std::to_string(o.tile[2]);
  }
  std::vector<BenchResult> results;
  std::vector<FlowBenchResult> flow;
  std::vector<RenderBenchResult> render;
  if (o.flow) flow.push_back(runFlowBench(packing));
  if (o.render) render.push_back(runRenderBench(packing, o.render_dir));
  if (!o.flow && !o.render) {
    for (int t : o.threads) results.push_back(runBench(packing, o, t));
  }
  printBench(std::cout, results, flow, render, json, source);
  return 0;
}

int runPackCommand(int dim, rocklab::PackingSpec spec, const std::string& dist, double dmin_mm,
                   double dmax_mm, double dmean_mm, double dstd_mm, double phi_mean, double phi_std,
                   const std::string& out) {
  using namespace rocklab;
  const double mm = 1e-3;
  if (dist == "uniform") {
    spec.sizes = SizeDistribution::uniform(dmin_mm * mm, dmax_mm * mm);
  } else if (dist == "normal") {
    spec.sizes = SizeDistribution::normal(dmean_mm * mm, dstd_mm * mm, dmin_mm * mm, dmax_mm * mm);
  } else {
    spec.sizes = SizeDistribution::phiGaussian(phi_mean, phi_std, dmin_mm * mm, dmax_mm * mm);
  }
  PackingReport report;
  std::ostringstream comment;
  comment << "rocklab pack: " << dim << "D, " << spec.count << " particles, "
          << spec.sizes.describe() << ", target porosity " << spec.porosity << ", seed "
          << spec.seed;
  auto finish = [&](const auto& packing) {
    comment << "\nporosity " << packing.porosity() << ", max overlap/r " << report.max_overlap
            << ", coordination " << report.coordination << ", " << report.steps << " steps";
    std::cout << comment.str() << "\n";
  };
  if (dim == 2) {
    const auto p = generatePacking<2>(spec, &report);
    finish(p);
    writePacking<2>(out, p, comment.str());
  } else {
    const auto p = generatePacking<3>(spec, &report);
    finish(p);
    writePacking<3>(out, p, comment.str());
  }
  std::cout << "wrote " << out << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // The chosen subcommand's work, run after parsing so errors are reported uniformly.
  std::function<int()> action;
  CLI::App app{
      "rocklab: a virtual rock laboratory. Runs laboratory protocols on numerical rock "
      "made of particles (DEM)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", versionLine());

  app.add_subcommand("version", "Print the version, git revision and build type")->callback([&] {
    action = [] {
      std::cout << versionLine() << "\n";
      return 0;
    };
  });

  app.add_subcommand("laws", "List the contact laws and the material parameters they read")
      ->callback([&] {
        action = [] {
          for (const auto* law : rocklab::contactLaws()) {
            std::cout << law->name << ": " << law->doc << "\n  protocol keys (with "
                      << "material.density_kg_per_m3, friction, damping_ratio):\n";
            for (const auto& k : law->keys) {
              std::cout << "    material." << k.field.key << " (" << k.field.unit.name
                        << "): " << k.field.doc << "\n";
            }
          }
          return 0;
        };
      });

  rocklab::BenchOptions bench;
  bool json = false;
  auto* b = app.add_subcommand(
      "bench",
      "Run the benchmark scene shared with LIGGGHTS and Yade (../shared/peers): Hertz-Mindlin, "
      "six walls closing in, dt 1.9e-7 s; prints particle-steps per second per thread count");
  b->add_option("--packing", bench.packing, "Packing file (N, walls, x y z r per line, metres)")
      ->check(CLI::ExistingFile);
  b->add_option("--n", bench.n, "Spheres in the generated packing (without --packing)")
      ->check(CLI::Range(2, 100000000));
  b->add_option("--steps", bench.steps, "Timed steps")->check(CLI::Range(1, 1000000000));
  b->add_option("--warmup", bench.warmup, "Untimed steps before");
  b->add_option("--threads", bench.threads, "Thread counts to run, e.g. --threads 1,2")
      ->delimiter(',')
      ->check(CLI::Range(1, 1024));
  b->add_option("--skin-m", bench.skin, "Verlet skin (m)")->check(CLI::Range(1e-9, 1.0));
  b->add_option("--seed", bench.seed, "Seed of the generated packing");
  b->add_flag("--energy", bench.energy, "Track contact dissipation (the peers do not)");
  b->add_option("--save-packing", bench.save_packing, "Write the generated packing to this file");
  b->add_option("--tile", bench.tile, "Copies of the packing along x,y,z, e.g. 5,5,4")
      ->delimiter(',')
      ->check(CLI::Range(1, 1000));
  b->add_flag("--bonded", bench.bonded, "A parallel bond on every initial contact");
  b->add_flag("--scalar-bonds", bench.scalar_bonds,
              "Bonds one at a time instead of four per AVX register (the same bits, slower)");
  b->add_flag("--flow", bench.flow,
              "Time the pore network (triangulation, network, steady solve) instead");
  b->add_flag("--render", bench.render,
              "Time an off-screen snapshot (bench-view.png, bench-slice.png) instead");
  b->add_option("--render-dir", bench.render_dir, "Folder of the snapshot's PNGs")
      ->check(CLI::ExistingDirectory);
  b->add_flag("--json", json, "Print JSON");
  b->callback([&] { action = [&] { return runBenchCommand(bench, json); }; });

  rocklab::cli::RunOptions run;
  auto* r = app.add_subcommand("run", "Run a protocol; every measurement goes to the lab notebook");
  r->add_option("protocol", run.protocol, "Protocol file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  r->add_option("--lab", run.lab, "Lab notebook (SQLite), created if missing");
  r->add_flag("--quiet", run.quiet, "No progress on stderr");
  r->add_option("--threads", run.threads, "Threads, instead of numerics.threads (same results)")
      ->check(CLI::Range(1, 1024));
  r->callback([&] { action = [&] { return rocklab::cli::runProtocol(run); }; });

  std::string check_file;
  auto* c = app.add_subcommand("check", "Validate a protocol without running it");
  c->add_option("protocol", check_file, "Protocol file (TOML)")->required();
  c->callback([&] { action = [&] { return rocklab::cli::checkProtocol(check_file); }; });

  std::string keys_rig;
  auto* k =
      app.add_subcommand("keys", "List a rig's protocol keys with units, defaults and ranges");
  k->add_option("rig", keys_rig,
                "oedometer, biaxial, envelope, hydrostatic, permeameter, ultrasonic")
      ->required();
  k->callback([&] { action = [&] { return rocklab::cli::listKeys(keys_rig); }; });

  rocklab::cli::NotebookOptions nbo;
  auto* nbc = app.add_subcommand("notebook", "Query the lab notebook");
  nbc->add_option("--lab", nbo.lab, "Lab notebook (SQLite)");
  nbc->add_flag("--csv", nbo.csv, "Print CSV");
  nbc->require_subcommand(1);
  nbc->add_subcommand("runs", "List the runs")->callback([&] { nbo.what = "runs"; });
  auto* show = nbc->add_subcommand("show", "A run: its row, parameters, results, timings");
  show->add_option("run", nbo.run, "Run id")->required();
  show->callback([&] { nbo.what = "show"; });
  auto* ser = nbc->add_subcommand("series", "A run's time series (long form)");
  ser->add_option("run", nbo.run, "Run id")->required();
  ser->add_option("names", nbo.names, "Series names (all when none)");
  ser->callback([&] { nbo.what = "series"; });
  auto* ev = nbc->add_subcommand("events", "A run's events (bond breaks ...)");
  ev->add_option("run", nbo.run, "Run id")->required();
  ev->add_option("--kind", nbo.kind, "Only events of this kind");
  ev->callback([&] { nbo.what = "events"; });
  auto* sql = nbc->add_subcommand("sql", "Any SQL query");
  sql->add_option("query", nbo.sql, "SQL")->required();
  sql->callback([&] { nbo.what = "sql"; });
  for (auto* sub : {show, ser, ev, sql, nbc->get_subcommand("runs")}) {
    sub->add_option("--lab", nbo.lab, "Lab notebook (SQLite)");
    sub->add_flag("--csv", nbo.csv, "Print CSV");
  }
  nbc->callback([&] { action = [&] { return rocklab::cli::notebookCommand(nbo); }; });

  rocklab::reports::ReportOptions report;
  report.data_dir = ROCKLAB_DATA_DIR;
  auto* rep =
      app.add_subcommand("report",
                         "Write a figure report of runs: index.html, PNG figures with their CSV, "
                         "snapshots rendered off screen, the paper's numbers beside the runs'");
  rep->add_option("runs", report.runs, "Run ids (their figures overlay)")->required();
  rep->add_option("--lab", report.lab, "Lab notebook (SQLite)");
  rep->add_option("--out", report.out, "Output folder")->required();
  rep->add_option("--field", report.field, "Snapshot colouring")
      ->check(CLI::IsMember({"displacement", "velocity", "broken_bonds", "grain"}));
  rep->add_option("--data", report.data_dir, "Folder holding paper.toml");
  rep->callback([&] {
    action = [&] {
      const auto s = rocklab::reports::writeReport(report);
      std::cout << "wrote " << report.out << "/index.html (" << s.files.size() << " files, "
                << static_cast<int>(s.seconds + 0.5) << " s)\n";
      return 0;
    };
  });

  std::string export_lab = "lab.sqlite", export_dir;
  std::int64_t export_run = 0;
  auto* exp = app.add_subcommand("export", "Write a run's state frames for ParaView");
  exp->add_option("run", export_run, "Run id")->required();
  exp->add_option("--vtk", export_dir, "Output folder (.vtp per frame and a .pvd)")->required();
  exp->add_option("--lab", export_lab, "Lab notebook (SQLite)");
  exp->callback([&] {
    action = [&] {
      std::cout << "wrote " << rocklab::reports::exportRun(export_lab, export_run, export_dir)
                << "\n";
      return 0;
    };
  });

  rocklab::cli::StudyOptions study;
  auto* st = app.add_subcommand("study", "Studies over many runs of a protocol");
  st->require_subcommand(1);
  auto* acc = st->add_subcommand(
      "accuracy",
      "Run a protocol over a ladder of numerical settings; report each setting's wall time and "
      "the deviation of the protocol's key results from the finest (the first value of each "
      "--vary), the Pareto front and the cheapest setting within --tolerance");
  acc->add_option("protocol", study.protocol, "Protocol file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  acc->add_option("--vary", study.vary,
                  "KEY=v1,v2,...: a protocol key and its values, finest first (repeat for more "
                  "keys: every combination runs)")
      ->required()
      ->allow_extra_args(false);
  acc->add_option("--lab", study.lab, "Lab notebook (SQLite), created if missing");
  acc->add_option("--out", study.out, "Output folder of the study report")->required();
  acc->add_option("--tolerance", study.tolerance_percent,
                  "Largest deviation of a key result accepted (%), to name the cheapest setting")
      ->check(CLI::Range(1e-6, 1e6));
  acc->add_option("--threads", study.threads, "Threads of every run (same results)")
      ->check(CLI::Range(1, 1024));
  acc->add_flag("--quiet", study.quiet, "No progress line on stderr");
  acc->add_flag("--dry-run", study.dry_run, "Check every setting and list them; run nothing");
  acc->callback([&] { action = [&] { return rocklab::cli::studyAccuracy(study); }; });

  std::vector<std::int64_t> study_runs;
  auto* sr = st->add_subcommand(
      "report", "Write the report of a study from its runs in the notebook, the finest first");
  sr->add_option("runs", study_runs, "Run ids of one protocol, the finest setting first")
      ->required();
  sr->add_option("--lab", study.lab, "Lab notebook (SQLite)");
  sr->add_option("--out", study.out, "Output folder of the study report")->required();
  sr->add_option("--tolerance", study.tolerance_percent,
                 "Largest deviation of a key result accepted (%), to name the cheapest setting")
      ->check(CLI::Range(1e-6, 1e6));
  sr->callback([&] {
    action = [&] {
      return rocklab::cli::studyReport(study_runs, study.lab, study.out, study.tolerance_percent);
    };
  });

  std::string reference, regress_lab = "lab.sqlite";
  std::int64_t regress_run = 0;
  rocklab::cli::RegressUpdateOptions update;
  auto* rg = app.add_subcommand(
      "regress", "Key results against reference files (the regression guard), and regenerate them");
  rg->require_subcommand(1);
  auto* rgc = rg->add_subcommand("check", "Compare a run's key results with a reference file");
  rgc->add_option("reference", reference, "Reference file (tests/reference/NAME.toml)")->required();
  rgc->add_option("--lab", regress_lab, "Lab notebook (SQLite)");
  rgc->add_option("--run", regress_run, "Run id (default: the newest run of the protocol)");
  rgc->callback([&] {
    action = [&] { return rocklab::cli::regressCheck(reference, regress_lab, regress_run); };
  });
  auto* rgu = rg->add_subcommand(
      "update",
      "Run protocols at several seeds and write their reference files: the value at the "
      "protocol's seed, the tolerance from the seeds' spread");
  rgu->add_option("protocols", update.protocols, "Protocol files")
      ->required()
      ->check(CLI::ExistingFile);
  rgu->add_option("--out", update.out, "Folder of the reference files");
  rgu->add_option("--lab", update.lab, "Lab notebook the runs go to");
  rgu->add_option("--seeds", update.seeds, "Seeds per protocol")->check(CLI::Range(2, 100));
  rgu->add_option("--threads", update.threads, "Threads of every run")->check(CLI::Range(1, 1024));
  rgu->callback([&] { action = [&] { return rocklab::cli::regressUpdate(update); }; });

  int dim = 3;
  rocklab::PackingSpec spec;
  std::string dist = "uniform", out;
  double dmin = 1.8, dmax = 2.2, dmean = 2.0, dstd = 0.1, phi_mean = -1.0, phi_std = 0.1;
  auto* p = app.add_subcommand(
      "pack",
      "Generate a packing: random placement, then radius expansion in a fixed box to a "
      "target porosity");
  p->add_option("--dim", dim, "2 (disks) or 3 (spheres)")->check(CLI::IsMember({2, 3}));
  p->add_option("--n", spec.count, "Particles")->check(CLI::Range(1, 50000000));
  p->add_option("--dist", dist, "Size distribution: uniform, normal or phi (Gaussian in phi)")
      ->check(CLI::IsMember({"uniform", "normal", "phi"}));
  p->add_option("--d-min-mm", dmin, "Smallest diameter (mm)")->check(CLI::PositiveNumber);
  p->add_option("--d-max-mm", dmax, "Largest diameter (mm)")->check(CLI::PositiveNumber);
  p->add_option("--d-mean-mm", dmean, "Mean diameter, normal distribution (mm)");
  p->add_option("--d-std-mm", dstd, "Diameter standard deviation, normal distribution (mm)");
  p->add_option("--phi-mean", phi_mean, "Mean of phi = -log2(d / 1 mm), phi distribution");
  p->add_option("--phi-std", phi_std, "Standard deviation of phi, phi distribution");
  p->add_option("--porosity", spec.porosity, "Target porosity (-)")->check(CLI::Range(0.01, 0.99));
  p->add_option("--thickness-m", spec.thickness, "Disk thickness in 2D (m)");
  p->add_option("--seed", spec.seed, "Random seed");
  p->add_option("--threads", spec.threads, "Threads")->check(CLI::Range(1, 1024));
  p->add_option("--out", out, "Output packing file")->required();
  p->callback([&] {
    action = [&] {
      return runPackCommand(dim, spec, dist, dmin, dmax, dmean, dstd, phi_mean, phi_std, out);
    };
  });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return action ? action() : 0;
  } catch (const std::exception& e) {
    std::cerr << "rocklab: " << e.what() << "\n";
    return 1;
  }
}
