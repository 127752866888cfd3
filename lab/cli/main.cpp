// The `rocklab` command.

#include <CLI/CLI.hpp>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>

#include "lab/cli/bench.hpp"
#include "lab/cli/build_info.hpp"
#include "lab/cli/calibrate_commands.hpp"
#include "lab/cli/campaign_commands.hpp"
#include "lab/cli/catalogue_commands.hpp"
#include "lab/cli/lab_commands.hpp"
#include "lab/cli/regress_commands.hpp"
#include "lab/cli/study_commands.hpp"
#include "lab/core/contact_laws.hpp"
#include "lab/core/packing_io.hpp"
#include "lab/samples/lattice.hpp"
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
  if (o.flow) flow.push_back(runFlowBench(packing, o.flow_strain));
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

struct LatticeOptions {
  std::string kind;  // empty: a random packing
  double spacing_mm = 2.0, radius_mm = 0.0, position = 0.0, radius = 0.0;
  std::vector<int> cells;
};

int runLatticeCommand(const LatticeOptions& o, std::uint64_t seed, const std::string& out) {
  using namespace rocklab;
  LatticeSpec spec;
  spec.kind = latticeKindOf(o.kind);
  const int dim = latticeDimension(spec.kind);
  if (static_cast<int>(o.cells.size()) != dim) {
    throw std::runtime_error("--cells: a " + o.kind + " lattice is " + std::to_string(dim) +
                             "D: give " + std::to_string(dim) + " counts, e.g. --cells " +
                             (dim == 2 ? "20,30" : "10,10,15"));
  }
  for (int a = 0; a < dim; ++a) spec.cells[a] = o.cells[a];
  spec.spacing = o.spacing_mm * 1e-3;
  spec.radius = o.radius_mm * 1e-3;
  spec.position_perturbation = o.position;
  spec.radius_perturbation = o.radius;
  spec.seed = seed;
  std::ostringstream comment;
  comment << "rocklab pack --lattice " << o.kind << ": spacing " << o.spacing_mm << " mm, radius "
          << (o.radius_mm > 0 ? o.radius_mm : 0.5 * o.spacing_mm) << " mm, cells";
  for (int c : o.cells) comment << " " << c;
  comment << ", perturbation of positions " << o.position << " and radii " << o.radius
          << " (relative), seed " << seed;
  auto finish = [&](const auto& p) {
    comment << "\n" << p.centers.size() << " particles, porosity " << p.porosity();
    std::cout << comment.str() << "\n";
    writePacking(out, p, comment.str());
  };
  if (dim == 2) {
    finish(latticePacking<2>(spec));
  } else {
    finish(latticePacking<3>(spec));
  }
  std::cout << "wrote " << out << "\n";
  return 0;
}

// A subcommand's work, set by its callback and run after parsing, so that errors are
// reported the same way whichever command failed.
using Action = std::function<int()>;

void addVersion(CLI::App& app, Action& action) {
  app.add_subcommand("version", "Print the version, git revision and build type")->callback([&] {
    action = [] {
      std::cout << versionLine() << "\n";
      return 0;
    };
  });
}

void addLaws(CLI::App& app, Action& action) {
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
}

void addBench(CLI::App& app, Action& action) {
  auto o = std::make_shared<rocklab::BenchOptions>();
  auto json = std::make_shared<bool>(false);
  auto* b = app.add_subcommand(
      "bench",
      "Run the benchmark scene shared with LIGGGHTS and Yade (data/peers): Hertz-Mindlin, six "
      "walls closing in, dt 1.9e-7 s; prints particle-steps per second per thread count");
  b->add_option("--packing", o->packing, "Packing file (N, walls, x y z r per line, metres)")
      ->check(CLI::ExistingFile);
  b->add_option("--n", o->n, "Spheres in the generated packing (without --packing)")
      ->check(CLI::Range(2, 100000000));
  b->add_option("--steps", o->steps, "Timed steps")->check(CLI::Range(1, 1000000000));
  b->add_option("--warmup", o->warmup, "Untimed steps before");
  b->add_option("--threads", o->threads, "Thread counts to run, e.g. --threads 1,2")
      ->delimiter(',')
      ->check(CLI::Range(1, 1024));
  b->add_option("--skin-m", o->skin, "Verlet skin (m)")->check(CLI::Range(1e-9, 1.0));
  b->add_option("--seed", o->seed, "Seed of the generated packing");
  b->add_flag("--energy", o->energy, "Track contact dissipation (the peers do not)");
  b->add_option("--save-packing", o->save_packing, "Write the generated packing to this file");
  b->add_option("--tile", o->tile, "Copies of the packing along x,y,z, e.g. 5,5,4")
      ->delimiter(',')
      ->check(CLI::Range(1, 1000));
  CLI::Option* bonded = b->add_flag(
      "--bonded", o->bonded, "A bond (parallel unless --bond-model) on every initial contact");
  b->add_option("--bond-model", o->bond_model,
                "The bonds' model: parallel, or flat_joint (2 rings of 3 elements, as PFC's)")
      ->check(CLI::IsMember({"parallel", "flat_joint"}))
      ->needs(bonded);
  b->add_flag(
      "--scalar-bonds", o->scalar_bonds,
      "Bonds one at a time instead of eight or four per vector register (the same bits, slower)");
  b->add_flag("--flow", o->flow,
              "Time the pore network (triangulation, network, steady solve) instead");
  b->add_option("--flow-strain", o->flow_strain,
                "Axial strain of the packing before the repeat flow call (moves the network)")
      ->check(CLI::Range(0.0, 0.01));
  b->add_flag("--render", o->render,
              "Time an off-screen snapshot (bench-view.png, bench-slice.png) instead");
  b->add_option("--render-dir", o->render_dir, "Folder of the snapshot's PNGs")
      ->check(CLI::ExistingDirectory);
  b->add_flag("--json", *json, "Print JSON");
  b->callback([&action, o, json] { action = [o, json] { return runBenchCommand(*o, *json); }; });
}

void addSet(CLI::App* command, std::vector<std::string>& sets) {
  command
      ->add_option("--set", sets,
                   "KEY=VALUE: a protocol key's value instead of the file's (repeatable); "
                   "checked like the file's keys, kept in the notebook's protocol text")
      ->take_all()
      ->allow_extra_args(false);
}

// The options every command that runs a protocol takes.
void addRunOptions(CLI::App* command, rocklab::cli::RunOptions& o, const std::string& lab_doc) {
  command->add_option("--lab", o.lab, lab_doc);
  command->add_flag("--quiet", o.quiet, "No progress on stderr");
  command->add_option("--threads", o.threads, "Threads, instead of numerics.threads (same results)")
      ->check(CLI::Range(1, 1024));
}

void addRun(CLI::App& app, Action& action) {
  auto o = std::make_shared<rocklab::cli::RunOptions>();
  auto* r = app.add_subcommand("run", "Run a protocol; every measurement goes to the lab notebook");
  r->add_option("protocol", o->protocol, "Protocol file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  addRunOptions(r, *o, "Lab notebook (SQLite), created if missing");
  addSet(r, o->sets);
  r->callback([&action, o] { action = [o] { return rocklab::cli::runProtocol(*o); }; });

  // rerun and resume: a run of the notebook, again or continued.
  using RunOf = int (*)(std::int64_t, const rocklab::cli::RunOptions&);
  auto addRunOf = [&](const char* name, const char* doc, const char* lab_doc, RunOf command,
                      bool with_set) {
    auto ro = std::make_shared<rocklab::cli::RunOptions>();
    auto run = std::make_shared<std::int64_t>(0);
    auto* c = app.add_subcommand(name, doc);
    c->add_option("run", *run, "Run id")->required();
    addRunOptions(c, *ro, lab_doc);
    if (with_set) addSet(c, ro->sets);
    c->callback([&action, ro, run, command] {
      action = [ro, run, command] { return command(*run, *ro); };
    });
  };
  addRunOf("rerun", "Run a run of the notebook again, from the protocol text the notebook kept",
           "Lab notebook (SQLite); the new run goes there too", &rocklab::cli::rerunProtocol, true);
  addRunOf("resume",
           "Continue a run that was killed, interrupted or stopped from its last checkpoint, in "
           "the same notebook row: it ends as an uninterrupted run would",
           "Lab notebook (SQLite)", &rocklab::cli::resumeRun, false);
}

void addCheckAndKeys(CLI::App& app, Action& action) {
  auto file = std::make_shared<std::string>();
  auto sets = std::make_shared<std::vector<std::string>>();
  auto* c = app.add_subcommand("check", "Validate a protocol without running it");
  c->add_option("protocol", *file, "Protocol file (TOML)")->required();
  addSet(c, *sets);
  auto print = std::make_shared<bool>(false);
  c->add_flag("--print", *print,
              "Print the protocol as it would run: with its includes, base and --set values "
              "written in, as the notebook keeps it");
  c->callback([&action, file, sets, print] {
    action = [file, sets, print] { return rocklab::cli::checkProtocol(*file, *sets, *print); };
  });

  auto rig = std::make_shared<std::string>();
  auto* k = app.add_subcommand(
      "keys", "List a rig's protocol keys (units, defaults, ranges), key results and outputs");
  k->add_option("rig", *rig, "oedometer, biaxial, envelope, hydrostatic, permeameter, ultrasonic")
      ->required();
  k->callback([&action, rig] { action = [rig] { return rocklab::cli::listKeys(*rig); }; });
}

void addNotebook(CLI::App& app, Action& action) {
  auto o = std::make_shared<rocklab::cli::NotebookOptions>();
  auto* nbc = app.add_subcommand("notebook", "Query the lab notebook");
  nbc->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  nbc->add_flag("--csv", o->csv, "Print CSV");
  nbc->require_subcommand(1);
  nbc->add_subcommand("runs", "List the runs")->callback([o] { o->what = "runs"; });
  auto* show = nbc->add_subcommand("show", "A run: its row, parameters, results, timings");
  show->add_option("run", o->run, "Run id")->required();
  show->callback([o] { o->what = "show"; });
  auto* ser = nbc->add_subcommand("series", "A run's time series (long form)");
  ser->add_option("run", o->run, "Run id")->required();
  ser->add_option("names", o->names, "Series names (all when none)");
  ser->callback([o] { o->what = "series"; });
  auto* ev = nbc->add_subcommand("events", "A run's events (bond breaks ...)");
  ev->add_option("run", o->run, "Run id")->required();
  ev->add_option("--kind", o->kind, "Only events of this kind");
  ev->callback([o] { o->what = "events"; });
  auto* sql = nbc->add_subcommand(
      "sql", "Any SQL query that reads (the notebook is opened read-only: writes are refused)");
  sql->add_option("query", o->sql, "SQL")->required();
  sql->callback([o] { o->what = "sql"; });
  auto* del = nbc->add_subcommand("delete", "Remove runs: their rows in every table and files");
  del->add_option("runs", o->runs, "Run ids")->required();
  del->add_flag("--yes", o->yes, "Confirm (without it, only lists what would be removed)");
  del->callback([o] { o->what = "delete"; });
  auto merge = std::make_shared<std::vector<std::string>>();
  auto* mrg = nbc->add_subcommand(
      "merge",
      "Copy the runs of other notebooks into the lab, with their files and where they "
      "came from (a run already there is not copied again)");
  mrg->add_option("notebooks", *merge, "Notebooks to merge in")->required();
  mrg->add_option("--lab", o->lab, "Lab notebook (SQLite) they go into");
  for (auto* sub : {show, ser, ev, sql, del, nbc->get_subcommand("runs")}) {
    sub->add_option("--lab", o->lab, "Lab notebook (SQLite)");
    sub->add_flag("--csv", o->csv, "Print CSV");
  }
  nbc->callback([&action, o, mrg, merge] {
    if (mrg->parsed()) {
      action = [o, merge] { return rocklab::cli::notebookMerge(o->lab, *merge); };
    } else {
      action = [o] { return rocklab::cli::notebookCommand(*o); };
    }
  });
}

void addReportAndExport(CLI::App& app, Action& action) {
  auto o = std::make_shared<rocklab::reports::ReportOptions>();
  o->data_dir = ROCKLAB_DATA_DIR;
  auto* rep =
      app.add_subcommand("report",
                         "Write a figure report of runs: index.html, PNG figures with their CSV, "
                         "snapshots rendered off screen, the paper's numbers beside the runs'");
  rep->add_option("runs", o->runs, "Run ids (their figures overlay)")->required();
  rep->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  rep->add_option("--out", o->out, "Output folder")->required();
  rep->add_option("--field", o->field, "Snapshot colouring")
      ->check(CLI::IsMember({"displacement", "velocity", "broken_bonds", "grain"}));
  rep->add_option("--data", o->data_dir, "Folder holding paper.toml");
  rep->callback([&action, o] {
    action = [o] {
      const auto s = rocklab::reports::writeReport(*o);
      std::cout << "wrote " << o->out << "/index.html (" << s.files.size() << " files, "
                << static_cast<int>(s.seconds + 0.5) << " s)\n";
      return 0;
    };
  });

  struct Export {
    std::string lab = "lab.sqlite", dir;
    std::int64_t run = 0;
  };
  auto e = std::make_shared<Export>();
  auto* exp = app.add_subcommand("export", "Write a run's state frames for ParaView");
  exp->add_option("run", e->run, "Run id")->required();
  exp->add_option("--vtk", e->dir, "Output folder (.vtp per frame and a .pvd)")->required();
  exp->add_option("--lab", e->lab, "Lab notebook (SQLite)");
  exp->callback([&action, e] {
    action = [e] {
      std::cout << "wrote " << rocklab::reports::exportRun(e->lab, e->run, e->dir) << "\n";
      return 0;
    };
  });
}

void addStudy(CLI::App& app, Action& action) {
  auto o = std::make_shared<rocklab::cli::StudyOptions>();
  auto* st = app.add_subcommand("study", "Studies over many runs of a protocol");
  st->require_subcommand(1);
  auto* acc = st->add_subcommand(
      "accuracy",
      "Run a protocol over a ladder of numerical settings; report each setting's wall time and "
      "the deviation of the protocol's key results from the finest (the first value of each "
      "--vary), the Pareto front and the cheapest setting within --tolerance");
  acc->add_option("protocol", o->protocol, "Protocol file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  acc->add_option("--vary", o->vary,
                  "KEY=v1,v2,...: a protocol key and its values, finest first (repeat for more "
                  "keys: every combination runs)")
      ->required()
      ->allow_extra_args(false);
  acc->add_option("--lab", o->lab, "Lab notebook (SQLite), created if missing");
  addSet(acc, o->sets);
  acc->add_option("--out", o->out, "Output folder of the study report")->required();
  acc->add_option("--tolerance", o->tolerance_percent,
                  "Largest deviation of a key result accepted (%), to name the cheapest setting")
      ->check(CLI::Range(1e-6, 1e6));
  acc->add_option("--seeds", o->seeds,
                  "Runs per setting at successive seeds: a deviation inside their scatter is "
                  "not a loss of accuracy")
      ->check(CLI::Range(1, 1000));
  acc->add_option("--threads", o->threads, "Threads of every run (same results)")
      ->check(CLI::Range(1, 1024));
  acc->add_flag("--quiet", o->quiet, "No progress line on stderr");
  acc->add_flag("--dry-run", o->dry_run, "Check every setting and list them; run nothing");
  acc->callback([&action, o] { action = [o] { return rocklab::cli::studyAccuracy(*o); }; });

  auto runs = std::make_shared<std::vector<std::int64_t>>();
  auto* sr = st->add_subcommand(
      "report",
      "Write the report of a study from its runs in the notebook, the finest first (runs that "
      "differ only in their seed are one setting)");
  sr->add_option("runs", *runs, "Run ids of one protocol, the finest setting first")->required();
  sr->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  sr->add_option("--out", o->out, "Output folder of the study report")->required();
  sr->add_option("--tolerance", o->tolerance_percent,
                 "Largest deviation of a key result accepted (%), to name the cheapest setting")
      ->check(CLI::Range(1e-6, 1e6));
  sr->callback([&action, o, runs] {
    action = [o, runs] {
      return rocklab::cli::studyReport(*runs, o->lab, o->out, o->tolerance_percent);
    };
  });
}

void addRegress(CLI::App& app, Action& action) {
  struct Check {
    std::string reference, lab = "lab.sqlite";
    std::int64_t run = 0;
  };
  auto c = std::make_shared<Check>();
  auto* rg = app.add_subcommand(
      "regress", "Key results against reference files (the regression guard), and regenerate them");
  rg->require_subcommand(1);
  auto* rgc = rg->add_subcommand(
      "check", "Compare the key results of the runs at the reference's seeds with the reference");
  rgc->add_option("reference", c->reference, "Reference file (tests/reference/NAME.toml)")
      ->required();
  rgc->add_option("--lab", c->lab, "Lab notebook (SQLite)");
  rgc->add_option("--run", c->run,
                  "One run (default: the newest run of the protocol at each of the reference's "
                  "seeds)");
  rgc->callback([&action, c] {
    action = [c] { return rocklab::cli::regressCheck(c->reference, c->lab, c->run); };
  });
  auto u = std::make_shared<rocklab::cli::RegressUpdateOptions>();
  auto* rgu = rg->add_subcommand(
      "update",
      "Run protocols at several seeds from their own and write their reference files: each key "
      "result's values at the seeds, their mean and standard deviation");
  rgu->add_option("protocols", u->protocols, "Protocol files")
      ->required()
      ->check(CLI::ExistingFile);
  rgu->add_option("--out", u->out, "Folder of the reference files");
  rgu->add_option("--lab", u->lab, "Lab notebook the runs go to");
  rgu->add_option("--seeds", u->seeds,
                  "Seeds per protocol, from its own (the check's interval narrows with them; "
                  "default: as many as its reference in --out has, 8 for a new one)")
      ->check(CLI::Range(2, 100));
  rgu->add_option("--threads", u->threads, "Threads of every run")->check(CLI::Range(1, 1024));
  rgu->add_option("--jobs", u->jobs,
                  "Runs at once, each a process of its own whose notebook is merged into the lab")
      ->check(CLI::Range(1, 256));
  rgu->callback([&action, u] { action = [u] { return rocklab::cli::regressUpdate(*u); }; });
}

void addPack(CLI::App& app, Action& action) {
  struct Pack {
    int dim = 3;
    rocklab::PackingSpec spec;
    std::string dist = "uniform", out;
    double dmin = 1.8, dmax = 2.2, dmean = 2.0, dstd = 0.1, phi_mean = -1.0, phi_std = 0.1;
  };
  auto o = std::make_shared<Pack>();
  auto l = std::make_shared<LatticeOptions>();
  auto* p = app.add_subcommand(
      "pack",
      "Generate a packing: random placement, then radius expansion in a fixed box to a "
      "target porosity; or a regular lattice (--lattice). Protocols read it with "
      "sample.kind = \"file\"");
  p->add_option("--lattice", l->kind,
                "A regular lattice instead: hex, square (2D), sc, bcc, fcc (3D)")
      ->check(CLI::IsMember({"hex", "square", "sc", "bcc", "fcc"}));
  p->add_option("--spacing-mm", l->spacing_mm, "Lattice: nearest-neighbour distance (mm)")
      ->check(CLI::PositiveNumber);
  p->add_option("--radius-mm", l->radius_mm,
                "Lattice: particle radius (mm; default half the spacing)")
      ->check(CLI::PositiveNumber);
  p->add_option("--cells", l->cells, "Lattice: unit cells along x,y[,z], e.g. 10,10,15")
      ->delimiter(',')
      ->check(CLI::Range(1, 100000));
  p->add_option("--perturb-position", l->position,
                "Lattice: each coordinate moved by up to this times the radius (uniform)")
      ->check(CLI::Range(0.0, 1.0));
  p->add_option("--perturb-radius", l->radius,
                "Lattice: each radius scaled by 1 + up to +- this (uniform)")
      ->check(CLI::Range(0.0, 0.9));
  p->add_option("--dim", o->dim, "2 (disks) or 3 (spheres)")->check(CLI::IsMember({2, 3}));
  p->add_option("--n", o->spec.count, "Particles")->check(CLI::Range(2, 50000000));
  p->add_option("--dist", o->dist, "Size distribution: uniform, normal or phi (Gaussian in phi)")
      ->check(CLI::IsMember({"uniform", "normal", "phi"}));
  p->add_option("--d-min-mm", o->dmin, "Smallest diameter (mm)")->check(CLI::PositiveNumber);
  p->add_option("--d-max-mm", o->dmax, "Largest diameter (mm)")->check(CLI::PositiveNumber);
  p->add_option("--d-mean-mm", o->dmean, "Mean diameter, normal distribution (mm)");
  p->add_option("--d-std-mm", o->dstd, "Diameter standard deviation, normal distribution (mm)");
  p->add_option("--phi-mean", o->phi_mean, "Mean of phi = -log2(d / 1 mm), phi distribution");
  p->add_option("--phi-std", o->phi_std, "Standard deviation of phi, phi distribution");
  p->add_option("--porosity", o->spec.porosity, "Target porosity (-)")
      ->check(CLI::Range(0.05, 0.9));
  p->add_option("--thickness-m", o->spec.thickness, "Disk thickness in 2D (m)");
  p->add_option("--seed", o->spec.seed, "Random seed");
  p->add_option("--threads", o->spec.threads, "Threads")->check(CLI::Range(1, 1024));
  p->add_option("--out", o->out, "Output packing file")->required();
  p->callback([&action, o, l] {
    action = [o, l] {
      if (!l->kind.empty()) return runLatticeCommand(*l, o->spec.seed, o->out);
      return runPackCommand(o->dim, o->spec, o->dist, o->dmin, o->dmax, o->dmean, o->dstd,
                            o->phi_mean, o->phi_std, o->out);
    };
  });
}

void addCalibrate(CLI::App& app, Action& action) {
  auto o = std::make_shared<rocklab::cli::CalibrateOptions>();
  auto* c = app.add_subcommand(
      "calibrate",
      "Fit protocol keys to measured properties: batches of evaluations over seeds, each a "
      "campaign (local pool or Slurm), resumed from the lab by running it again");
  c->add_option("calibration", o->file, "Calibration file (TOML)")->required();
  c->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  c->add_option("--jobs", o->jobs, "Local pool: runs at once (default: cores / threads)")
      ->check(CLI::Range(1, 4096));
  c->add_option("--scheduler", o->scheduler, "local (a pool of processes) or slurm (sbatch)")
      ->check(CLI::IsMember({"local", "slurm"}));
  c->add_option("--report", o->report,
                "The report's folder (default: <lab>.calibrations/NAME/report)");
  c->add_flag("--check", o->check_only, "Validate the file and its protocols; run nothing");
  c->add_flag("--quiet", o->quiet, "No progress lines from the campaigns");
  c->callback([&action, o] { action = [o] { return rocklab::cli::calibrate(*o); }; });
}

void addCampaign(CLI::App& app, Action& action) {
  auto o = std::make_shared<rocklab::cli::CampaignOptions>();
  auto* c = app.add_subcommand(
      "campaign",
      "A protocol over seeds and sweeps of its keys: every point x seed a run of its own "
      "process, on a local pool or a Slurm job array, merged into the lab with each point's "
      "statistics");
  c->require_subcommand(1);
  auto file = [&](CLI::App* sub) {
    sub->add_option("campaign", o->file, "Campaign file (TOML)")->required();
  };
  auto* run = c->add_subcommand("run", "Run the campaign's tasks not done yet");
  file(run);
  run->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  run->add_option("--jobs", o->jobs, "Local pool: runs at once (default: cores / threads)")
      ->check(CLI::Range(1, 4096));
  run->add_option("--scheduler", o->scheduler, "local (a pool of processes) or slurm (sbatch)")
      ->check(CLI::IsMember({"local", "slurm"}));
  run->add_flag("--wait", o->wait, "slurm: wait for the job array and collect it here");
  run->add_flag("--rerun-failed", o->rerun_failed,
                "Run the failed and killed tasks again (from their checkpoints where kept)");
  run->add_flag("--quiet", o->quiet, "No progress line");
  run->callback([&action, o] { action = [o] { return rocklab::cli::campaignRun(*o); }; });
  auto* check = c->add_subcommand("check", "Validate the campaign file and every point's protocol");
  file(check);
  check->callback([&action, o] { action = [o] { return rocklab::cli::campaignCheck(*o); }; });
  auto* task = c->add_subcommand(
      "task", "Run one task into its shard (what the pool's processes and Slurm's tasks run)");
  file(task);
  task->add_option("--task", o->task, "The task's index")->required();
  task->add_option("--shard-dir", o->shard_dir, "Folder of the campaign's shards")->required();
  task->add_option("--scratch", o->scratch, "Local storage to run in, the shard moved after");
  task->add_flag("--quiet", o->quiet, "No progress line");
  task->callback([&action, o] { action = [o] { return rocklab::cli::campaignTask(*o); }; });
  auto* collect = c->add_subcommand(
      "collect", "Merge the campaign's shards into the lab and update its statistics");
  file(collect);
  collect->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  collect->add_flag("--quiet", o->quiet, "Nothing but problems");
  collect->callback([&action, o] { action = [o] { return rocklab::cli::campaignCollect(*o); }; });
  auto* show = c->add_subcommand(
      "show", "Each point's key results over its seeds: n, mean, std and 95% interval");
  file(show);
  show->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  show->callback([&action, o] { action = [o] { return rocklab::cli::campaignShow(*o); }; });
  o->data_dir = ROCKLAB_DATA_DIR;
  auto* report = c->add_subcommand(
      "report",
      "Write the campaign's report: each point's key results over its seeds and each rig's "
      "figures with their spread (mean and a band of one standard deviation)");
  file(report);
  report->add_option("--lab", o->lab, "Lab notebook (SQLite)");
  report->add_option("--out", o->out, "Output folder")->required();
  report->add_option("--data", o->data_dir, "Folder holding paper.toml");
  report->callback([&action, o] { action = [o] { return rocklab::cli::campaignReport(*o); }; });
  auto cat = std::make_shared<rocklab::cli::CatalogueOptions>();
  cat->data_dir = ROCKLAB_DATA_DIR;
  auto* catalogue = c->add_subcommand(
      "catalogue",
      "The paper's experiments beside the paper's numbers: each campaign's [[paper]] claims "
      "against its ensemble in the lab (mean and 95% interval, or the fraction of seeds), as "
      "a Markdown table");
  catalogue->add_option("campaigns", cat->files, "Campaign files (TOML)")->required();
  catalogue->add_option("--lab", cat->lab, "Lab notebook (SQLite)");
  catalogue->add_option("--out", cat->out, "Markdown file (default: standard output)");
  catalogue->add_option("--data", cat->data_dir, "Folder holding paper.toml");
  catalogue->callback(
      [&action, cat] { action = [cat] { return rocklab::cli::campaignCatalogue(*cat); }; });
}

}  // namespace

int main(int argc, char** argv) {
  Action action;
  CLI::App app{
      "rocklab: a virtual rock laboratory. Runs laboratory protocols on numerical rock "
      "made of particles (DEM)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", versionLine());
  addVersion(app, action);
  addLaws(app, action);
  addBench(app, action);
  addRun(app, action);
  addCheckAndKeys(app, action);
  addNotebook(app, action);
  addReportAndExport(app, action);
  addStudy(app, action);
  addRegress(app, action);
  addPack(app, action);
  addCampaign(app, action);
  addCalibrate(app, action);
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
