#include "lab/cli/campaign_commands.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "lab/campaign/campaign.hpp"
#include "lab/campaign/ledger.hpp"
#include "lab/cli/child_process.hpp"
#include "lab/cli/lab_commands.hpp"
#include "lab/notebook/merge.hpp"
#include "reports/campaign_report.hpp"
#include "rigs/common/formed_samples.hpp"
#include "rigs/registry.hpp"

namespace rocklab::cli {

namespace fs = std::filesystem;

namespace {

std::atomic<int> g_stop{0};
extern "C" void onCampaignSignal(int sig) {
  g_stop.store(sig);
}

// The campaign's folder beside the lab: the shards of its tasks, their logs, the Slurm
// scripts.
std::string campaignDir(const std::string& lab, const std::string& name) {
  return fs::absolute(lab).string() + ".campaigns/" + name;
}

std::string shardOf(const std::string& dir, int task) {
  return dir + "/task-" + std::to_string(task) + ".sqlite";
}

std::string shellQuoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string seconds(double s) {
  std::ostringstream o;
  if (s >= 3600) {
    o << static_cast<int>(s / 3600) << "h" << std::setw(2) << std::setfill('0')
      << static_cast<int>(s / 60) % 60 << "m";
  } else if (s >= 60) {
    o << static_cast<int>(s / 60) << "m" << std::setw(2) << std::setfill('0')
      << static_cast<int>(s) % 60 << "s";
  } else {
    o << static_cast<int>(s + 0.5) << "s";
  }
  return o.str();
}

// Every task's protocol checked, problems named by the campaign file's lines; returns the
// tasks' protocol hashes (what tells their runs in the lab).
std::vector<std::string> checkTasks(const campaign::Campaign& c) {
  std::vector<std::string> problems;
  std::set<std::string> seen;
  for (const campaign::Task& t : c.tasks()) {
    try {
      rigs::checkProtocol(c.protocol, c.overrides(t, true));
    } catch (const protocol::ProtocolError& e) {
      for (const auto& p : e.problems()) {
        if (seen.insert(p).second) problems.push_back(p);
      }
    }
  }
  if (!problems.empty()) throw protocol::ProtocolError(problems);
  std::vector<std::string> hashes;
  for (const campaign::Task& t : c.tasks()) hashes.push_back(campaign::taskProtocolHash(c, t));
  return hashes;
}

// Moves a notebook (closed) and its files; across file systems by copying.
void moveNotebook(const std::string& from, const std::string& to) {
  for (const std::string suffix : notebook::kNotebookParts) {
    const fs::path a = from + suffix, b = to + suffix;
    if (!fs::exists(a)) continue;
    fs::remove_all(b);
    std::error_code ec;
    fs::rename(a, b, ec);
    if (ec) {
      fs::copy(a, b, fs::copy_options::recursive);
      fs::remove_all(a);
    }
  }
}

// Where a task's shard was made: what its task wrote beside it (the scheduler's ids).
notebook::Provenance originOf(const std::string& dir, int task) {
  notebook::Provenance p;
  p.task_id = task;
  std::ifstream in(dir + "/task-" + std::to_string(task) + ".origin");
  for (std::string key, value; in >> key >> value;) {
    if (key == "scheduler") p.scheduler = value;
    if (key == "job") p.job_id = value;
  }
  return p;
}

// Merges a task's shard into the lab and returns the task with its run there; a completed
// shard is removed (the lab has all of it), one that failed stays, for a rerun to resume
// from its checkpoint.
campaign::TaskState collectShard(notebook::Notebook& lab, campaign::TaskState t,
                                 const std::string& dir) {
  const std::string shard = shardOf(dir, t.task.index);
  if (!fs::exists(shard)) return t;
  std::string uuid, status;
  {
    notebook::Notebook s(shard);  // a run whose process is gone is closed as failed
    auto q = s.db().prepare("SELECT uuid, status FROM runs ORDER BY id DESC LIMIT 1");
    if (!q.step()) return t;
    uuid = q.text(0);
    status = q.text(1);
  }
  if (status == "running") return t;  // still at work
  notebook::mergeNotebook(lab, shard, originOf(dir, t.task.index));
  auto q = lab.db().prepare("SELECT id, status, coalesce(reason, '') FROM runs WHERE uuid = ?");
  q.bind(1, uuid);
  if (q.step()) {
    t.run = q.integer(0);
    t.status = q.text(1);
    t.reason = q.text(2);
  }
  if (status == "completed") {
    notebook::removeNotebook(shard);
    for (const char* ext : {".log", ".origin"}) {
      fs::remove(dir + "/task-" + std::to_string(t.task.index) + ext);
    }
  }
  return t;
}

// The whole campaign on one line: done, running, failed, time left. On a terminal the line
// is redrawn in place; off one (a log file, a batch job's output) each task's end is a line
// of its own, so that a log shows how the campaign went.
class Progress {
 public:
  Progress(std::size_t total, std::size_t done, int jobs, bool show)
      : total_(total), done_(done), jobs_(jobs), show_(show), tty_(isatty(STDERR_FILENO)) {}
  void started() { ++running_; }
  void ended(const std::string& name, const campaign::TaskState& t, double seconds_taken) {
    const bool ok = t.status == "completed";
    --running_;
    ++(ok ? done_ : failed_);
    ++timed_;
    spent_ += seconds_taken;
    if (show_ && !tty_) {
      std::cerr << "campaign " << name << ": task " << t.task.index << " (point " << t.task.point
                << ", seed " << t.task.seed << ") " << (t.status.empty() ? "lost" : t.status)
                << " after " << seconds(seconds_taken) << "; " << state() << "\n";
    }
  }
  void print(const std::string& name, bool last = false) const {
    if (!show_) return;
    const std::string line = "campaign " + name + ": " + state();
    if (tty_) {
      std::cerr << "\r" << line << "\033[K" << (last ? "\n" : "") << std::flush;
    } else if (last) {
      std::cerr << line << "\n";
    }
  }

 private:
  std::string state() const {
    std::ostringstream line;
    line << done_ << "/" << total_ << " done, " << running_ << " running, " << failed_ << " failed";
    const std::size_t left = total_ - done_ - failed_;
    if (timed_ > 0 && left > 0) {
      line << ", " << seconds(spent_ / timed_ * left / std::max(1, jobs_)) << " left";
    }
    return line.str();
  }
  std::size_t total_, done_, failed_ = 0, running_ = 0, timed_ = 0;
  int jobs_;
  bool show_, tty_;
  double spent_ = 0.0;
};

// `rocklab campaign task` as a child process, its output to the task's log.
pid_t spawnTask(const campaign::Campaign& c, const std::string& dir, int task) {
  return spawnLogged({selfExecutable(), "campaign", "task", fs::absolute(c.file).string(), "--task",
                      std::to_string(task), "--shard-dir", dir, "--quiet"},
                     dir + "/task-" + std::to_string(task) + ".log");
}

// What is left to run: not completed, and (unless asked to rerun them) not failed.
std::vector<campaign::TaskState> toRun(const std::vector<campaign::TaskState>& states,
                                       bool rerun_failed) {
  std::vector<campaign::TaskState> out;
  for (const auto& t : states) {
    if (t.status == "completed") continue;
    if (!t.status.empty() && t.status != "running" && !rerun_failed) continue;
    out.push_back(t);
  }
  return out;
}

void listFailed(const campaign::Campaign& c, const std::vector<campaign::TaskState>& states) {
  bool any = false;
  for (const auto& t : states) {
    if (t.status.empty() || t.status == "completed" || t.status == "running") continue;
    if (!any) std::cerr << "failed tasks (`campaign run --rerun-failed` runs them again):\n";
    any = true;
    std::cerr << "  task " << t.task.index << " ("
              << c.points[static_cast<std::size_t>(t.task.point)].label() << ", seed "
              << t.task.seed << "): run " << t.run << " " << t.status << ": " << t.reason << "\n";
  }
}

struct Opened {
  campaign::Campaign c;
  std::vector<std::string> hashes;
};

std::optional<Opened> openCampaign(const CampaignOptions& o) {
  try {
    Opened x{campaign::readCampaign(o.file), {}};
    x.hashes = checkTasks(x.c);
    return x;
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return std::nullopt;
  }
}

// Merges every shard lying in the campaign's folder; returns the tasks' states after.
std::vector<campaign::TaskState> collectAll(notebook::Notebook& lab, std::int64_t id,
                                            const Opened& x, const std::string& dir) {
  std::vector<campaign::TaskState> states = campaign::survey(lab, x.c, x.hashes);
  for (auto& t : states) {
    t = collectShard(lab, t, dir);
    if (t.run > 0) campaign::recordTask(lab, id, x.c, t);
  }
  campaign::updateStatistics(lab, id, x.c);
  return states;
}

int summary(const campaign::Campaign& c, const std::vector<campaign::TaskState>& states) {
  std::size_t done = 0;
  for (const auto& t : states) done += t.status == "completed";
  listFailed(c, states);
  std::cerr << "campaign " << c.name << ": " << done << " of " << states.size()
            << " runs completed\n";
  return done == states.size() ? 0 : 1;
}

int runLocal(const CampaignOptions& o, const Opened& x) {
  const campaign::Campaign& c = x.c;
  notebook::Notebook lab(o.lab);
  const std::string dir = campaignDir(o.lab, c.name);
  fs::create_directories(dir);
  const std::int64_t id = campaign::registerCampaign(lab, c);
  std::vector<campaign::TaskState> states = collectAll(lab, id, x, dir);
  std::vector<campaign::TaskState> queue = toRun(states, o.rerun_failed);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int jobs = o.jobs > 0 ? o.jobs : std::max(1, cores / std::max(1, c.threads));
  Progress progress(states.size(), states.size() - toRun(states, true).size(), jobs, !o.quiet);
  std::cerr << "campaign " << c.name << ": " << queue.size() << " of " << states.size()
            << " runs to do, " << jobs << " at a time -> " << o.lab << "\n";
  g_stop.store(0);
  std::signal(SIGINT, onCampaignSignal);
  std::signal(SIGTERM, onCampaignSignal);
  std::map<pid_t, std::pair<std::size_t, std::chrono::steady_clock::time_point>> running;
  std::size_t next = 0;
  while (next < queue.size() || !running.empty()) {
    while (g_stop.load() == 0 && next < queue.size() && static_cast<int>(running.size()) < jobs) {
      running[spawnTask(c, dir, queue[next].task.index)] = {next, std::chrono::steady_clock::now()};
      ++next;
      progress.started();
    }
    progress.print(c.name);
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;  // a signal: the children have it too; wait for them
      break;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const auto [k, t0] = it->second;
    running.erase(it);
    const campaign::TaskState t = collectShard(lab, queue[k], dir);
    if (t.run > 0) campaign::recordTask(lab, id, c, t);
    states[static_cast<std::size_t>(t.task.index)] = t;
    progress.ended(c.name, t,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (g_stop.load() != 0) next = queue.size();  // interrupted: start nothing more
  }
  progress.print(c.name, true);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  campaign::updateStatistics(lab, id, c);
  const int code = summary(c, states);
  return g_stop.load() != 0 ? 130 : code;
}

// A command's output (sbatch --parsable, squeue), or throws with what it said.
std::string capture(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) throw std::runtime_error("cannot run: " + command);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int rc = pclose(p);
  if (rc != 0) throw std::runtime_error(command + " failed:\n" + out);
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

std::string writeScript(const std::string& path, const std::string& body) {
  std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
  fs::permissions(path, fs::perms::owner_all | fs::perms::group_read | fs::perms::others_read);
  return path;
}

// The campaign's tasks left as one Slurm job array; the shards are collected by a job that
// waits for it, or here (--wait).
int runSlurm(const CampaignOptions& o, const Opened& x) {
  const campaign::Campaign& c = x.c;
  const std::string dir = campaignDir(o.lab, c.name);
  fs::create_directories(dir);
  std::vector<campaign::TaskState> states;
  {
    notebook::Notebook lab(o.lab);
    const std::int64_t id = campaign::registerCampaign(lab, c);
    states = collectAll(lab, id, x, dir);
  }
  const std::vector<campaign::TaskState> queue = toRun(states, o.rerun_failed);
  if (queue.empty()) return summary(c, states);
  const std::string exe = selfExecutable();
  const std::string file = fs::absolute(c.file).string();
  // Each task runs on its node's local storage ($TMPDIR) and moves its shard to the
  // campaign's folder when it ends: a SQLite file is never written over a network file system.
  const std::string task = writeScript(
      dir + "/task.sh", "exec " + shellQuoted(exe) + " campaign task " + shellQuoted(file) +
                            " --task \"$SLURM_ARRAY_TASK_ID\" --shard-dir " + shellQuoted(dir) +
                            " --scratch \"${TMPDIR:-/tmp}\" --quiet");
  std::string array;
  for (const auto& t : queue) {
    if (!array.empty()) array += ',';
    array += std::to_string(t.task.index);
  }
  const campaign::SlurmOptions& s = c.slurm;
  std::string sbatch =
      "sbatch --parsable --job-name=" + shellQuoted("rocklab-" + c.name) + " --array=" + array +
      " --cpus-per-task=" + std::to_string(s.cpus_per_task > 0 ? s.cpus_per_task : c.threads) +
      " --output=" + shellQuoted(dir + "/slurm-%A_%a.out");
  if (!s.partition.empty()) sbatch += " --partition=" + shellQuoted(s.partition);
  if (!s.time.empty()) sbatch += " --time=" + shellQuoted(s.time);
  if (!s.account.empty()) sbatch += " --account=" + shellQuoted(s.account);
  for (const auto& opt : s.options) sbatch.append(" ").append(shellQuoted(opt));
  const std::string job = capture(sbatch + " " + shellQuoted(task));
  const std::string job_id = job.substr(0, job.find(';'));
  std::cerr << "campaign " << c.name << ": " << queue.size() << " of " << states.size()
            << " runs submitted as Slurm job array " << job_id << "\n";
  if (!o.wait) {
    const std::string collect =
        writeScript(dir + "/collect.sh",
                    "exec " + shellQuoted(exe) + " campaign collect " + shellQuoted(file) +
                        " --lab " + shellQuoted(fs::absolute(o.lab).string()) + " --quiet");
    const std::string cjob =
        capture("sbatch --parsable --job-name=" + shellQuoted("rocklab-" + c.name + "-collect") +
                " --dependency=afterany:" + job_id + " --output=" +
                shellQuoted(dir + "/slurm-collect-%j.out") + " " + shellQuoted(collect));
    std::cerr << "its shards are merged into " << o.lab << " by job "
              << cjob.substr(0, cjob.find(';')) << " when it ends (or: rocklab campaign collect "
              << o.file << " --lab " << o.lab << ")\n";
    std::cout << job_id << "\n";
    return 0;
  }
  // Waits for the array to leave the queue, then collects here.
  for (;;) {
    const std::string left = capture("squeue -h -j " + job_id + " -o %i");
    if (left.empty()) break;
    std::this_thread::sleep_for(std::chrono::seconds(2));
  }
  CampaignOptions collect = o;
  return campaignCollect(collect);
}

}  // namespace

int campaignCheck(const CampaignOptions& o) {
  const auto x = openCampaign(o);
  if (!x) return 2;
  const rigs::CheckedProtocol p = rigs::checkProtocol(x->c.protocol);
  std::cout << o.file << ": a valid campaign: " << x->c.points.size() << " points x "
            << x->c.seeds.size() << " seeds = " << x->c.tasks().size() << " runs of "
            << x->c.protocol << " (" << p.rig->name << ")\n";
  return 0;
}

int campaignRun(const CampaignOptions& o) {
  const auto x = openCampaign(o);
  if (!x) return 2;
  try {
    if (o.scheduler == "slurm") return runSlurm(o, *x);
    return runLocal(o, *x);
  } catch (const std::exception& e) {
    std::cerr << "campaign " << x->c.name << ": " << e.what() << "\n";
    return 1;
  }
}

int campaignTask(const CampaignOptions& o) {
  campaign::Campaign c;
  try {
    c = campaign::readCampaign(o.file);
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  const std::vector<campaign::Task> tasks = c.tasks();
  if (o.task < 0 || o.task >= static_cast<int>(tasks.size())) {
    std::cerr << "campaign " << c.name << " has tasks 0 to " << tasks.size() - 1 << ", not "
              << o.task << "\n";
    return 2;
  }
  const campaign::Task& t = tasks[static_cast<std::size_t>(o.task)];
  fs::create_directories(o.shard_dir);
  const std::string shard = shardOf(o.shard_dir, t.index);
  {
    const char* job = std::getenv("SLURM_ARRAY_JOB_ID");
    std::ofstream(o.shard_dir + "/task-" + std::to_string(t.index) + ".origin")
        << "scheduler " << (job ? "slurm" : "local") << "\n"
        << (job ? std::string("job ") + job + "\n" : std::string());
  }
  // What the shard holds already: a completed run, one to resume, or nothing usable.
  std::string status;
  if (fs::exists(shard)) {
    notebook::Notebook nb(shard);  // a run whose process is gone is closed as failed
    auto q = nb.db().prepare("SELECT status FROM runs WHERE id = 1");
    if (q.step()) status = q.text(0);
  }
  if (status == "running") {
    std::cerr << "task " << t.index << " of campaign " << c.name << " is running already (" << shard
              << ")\n";
    return 1;
  }
  if (status == "completed") return 0;
  if (!fs::exists(shard + ".files/run-1/checkpoints/journal")) notebook::removeNotebook(shard);
  // On local storage when asked, under the shard's own name (its files' paths name it).
  std::string work = shard;
  if (!o.scratch.empty()) {
    const std::string scratch = o.scratch + "/rocklab-" + c.name + "-" + std::to_string(getpid());
    fs::create_directories(scratch);
    work = scratch + "/" + fs::path(shard).filename().string();
    moveNotebook(shard, work);
  }
  // The formed samples (formation.reuse) of the lab the campaign runs for, which all its
  // tasks share: the shard folder is campaignDir(lab, name).
  fs::path shards = fs::absolute(o.shard_dir).lexically_normal();
  if (!shards.has_filename()) shards = shards.parent_path();  // given with a trailing '/'
  std::string lab = shards.parent_path().string();
  if (lab.ends_with(".campaigns")) lab.resize(lab.size() - std::string_view(".campaigns").size());
  const std::string formed = rigs::formedSamplesDir(lab);
  int code = 0;
  bool fresh = !fs::exists(work);
  if (!fresh) {
    RunOptions r;
    r.lab = work;
    r.quiet = o.quiet;
    r.threads = c.threads;
    r.formed_dir = formed;
    code = resumeRun(1, r);
    fresh = code == 2;  // it cannot resume (its protocol or rocklab changed): run it anew
    if (fresh) notebook::removeNotebook(work);
  }
  if (fresh) {
    try {
      const rigs::CheckedProtocol p = rigs::checkProtocol(c.protocol, c.overrides(t));
      protocol::Settings settings = p.settings;
      settings.runChoice("numerics.threads", static_cast<std::int64_t>(c.threads));
      code = runSettings(*p.rig, settings, c.protocol, work, o.quiet, 0, formed).code;
    } catch (const protocol::ProtocolError& e) {
      std::cerr << e.what() << "\n";
      code = 2;
    }
  }
  if (work != shard) {
    moveNotebook(work, shard);
    fs::remove_all(fs::path(work).parent_path());
  }
  return code;
}

int campaignCollect(const CampaignOptions& o) {
  const auto x = openCampaign(o);
  if (!x) return 2;
  try {
    notebook::Notebook lab(o.lab);
    const std::int64_t id = campaign::registerCampaign(lab, x->c);
    return summary(x->c, collectAll(lab, id, *x, campaignDir(o.lab, x->c.name)));
  } catch (const std::exception& e) {
    std::cerr << "campaign " << x->c.name << ": " << e.what() << "\n";
    return 1;
  }
}

int campaignShow(const CampaignOptions& o) {
  const auto x = openCampaign(o);
  if (!x) return 2;
  const campaign::Campaign& c = x->c;
  notebook::Notebook lab(o.lab);
  auto q = lab.db().prepare("SELECT id FROM campaigns WHERE name = ?");
  q.bind(1, c.name);
  if (!q.step()) {
    std::cerr << "campaign " << c.name << " has not run in " << o.lab << "\n";
    return 1;
  }
  const std::int64_t id = q.integer(0);
  const auto states = campaign::survey(lab, c, x->hashes);
  const rigs::CheckedProtocol p = rigs::checkProtocol(c.protocol, c.fixed);
  std::cout << "campaign " << c.name << ": " << c.protocol << " (" << p.rig->name << "), "
            << c.points.size() << " points x " << c.seeds.size() << " seeds\n";
  const std::vector<std::string>& keys = p.settings.texts("protocol.key_results");
  auto stat = lab.db().prepare(
      "SELECT n, mean, std, ci95_low, ci95_high, unit FROM campaign_statistics WHERE "
      "campaign_id = ? AND point = ? AND name = ?");
  for (const campaign::Point& point : c.points) {
    std::size_t done = 0, failed = 0;
    for (const auto& t : states) {
      if (t.task.point != point.index) continue;
      done += t.status == "completed";
      failed += !t.status.empty() && t.status != "completed" && t.status != "running";
    }
    std::cout << "\npoint " << point.index << " (" << point.label() << "): " << done << "/"
              << c.seeds.size() << " runs completed" << (failed ? ", " : "")
              << (failed ? std::to_string(failed) + " failed" : "") << "\n";
    std::cout << "  " << std::left << std::setw(36) << "key result" << std::right << std::setw(4)
              << "n" << std::setw(14) << "mean" << std::setw(12) << "std"
              << "   95% CI\n";
    for (const std::string& key : keys) {
      stat.bind(1, id).bind(2, point.index).bind(3, key);
      if (stat.step()) {
        std::ostringstream ci;
        if (!stat.isNull(3)) {
          ci << "[" << std::setprecision(5) << stat.real(3) << ", " << stat.real(4) << "]";
        }
        std::cout << "  " << std::left << std::setw(36) << key << std::right << std::setw(4)
                  << stat.integer(0) << std::setw(14) << std::setprecision(6) << stat.real(1)
                  << std::setw(12) << std::setprecision(3) << stat.real(2) << "   " << ci.str()
                  << " " << stat.text(5) << "\n";
      }
      stat.reset();
    }
  }
  listFailed(c, states);
  return 0;
}

int campaignReport(const CampaignOptions& o) {
  const auto x = openCampaign(o);
  if (!x) return 2;
  try {
    const auto s = reports::writeCampaignReport({o.lab, x->c.name, o.out, o.data_dir});
    std::cout << "wrote " << o.out << "/index.html (" << s.files.size() << " files, "
              << static_cast<int>(s.seconds + 0.5) << " s)\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    std::cerr << "campaign " << x->c.name << ": " << e.what() << "\n";
    return 1;
  }
}

int notebookMerge(const std::string& into, const std::vector<std::string>& sources) {
  try {
    notebook::Notebook lab(into);
    for (const std::string& s : sources) {
      if (!fs::exists(s)) {
        std::cerr << "no lab notebook at '" << s << "'\n";
        return 2;
      }
      const notebook::MergeOutcome m = notebook::mergeNotebook(lab, s, {});
      std::cout << s << ": " << m.runs.size() << " runs merged into " << into;
      if (m.already > 0) std::cout << ", " << m.already << " there already";
      std::cout << "\n";
      for (std::size_t k = 0; k < m.runs.size(); ++k) {
        std::cout << "  run " << m.source_runs[k] << " -> run " << m.runs[k] << "\n";
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "merge: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace rocklab::cli
