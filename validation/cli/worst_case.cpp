// warpcheck worst-case / warpcheck merge: run a worst-case error search (validation/.../searches.h),
// resumably and shardably, and combine shard results.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "commands.h"
#include "warpcheck/validation/searches.h"
#include "warpcheck/validation/shards.h"

namespace warpcheck::cli {

using namespace warpcheck::validation;

namespace {

const char* kWorstCaseHelp = R"(usage: warpcheck worst-case --search NAME [options]
       warpcheck worst-case --list

Maximises an error measure with multi-start Nelder-Mead in long double and reports the worst input found.

  --search NAME        the search to run (see --list)
  --seconds T          total wall-clock budget in seconds, counted over resumes (default 60)
  --threads N          worker threads (default 1)
  --seed S             seed; chain c of the search is a pure function of (S, c) (default 1)
  --shard I/N          run only chains c with c mod N == I (default 0/1); shards with the same seed are disjoint
  --checkpoint FILE    resume from FILE if it exists, and rewrite it atomically every --checkpoint-every
                       seconds, within 0.25 s of every improvement of the best-so-far, and at the end; a run
                       killed (even by SIGKILL) and restarted with the same command loses no best-so-far and
                       continues with the chains not yet done
  --checkpoint-every S seconds between checkpoint writes (default 10)
  --progress S         seconds between progress lines on stderr (default 5; 0 = none)
  --json FILE          write the result there (atomically) instead of to stdout
  --list               list the searches with their parameter boxes and exit
  --evaluate FILE      print the objective of --search at the input recorded in FILE (a result, checkpoint
                       or data/worst-cases record of a search with the same parameters) and exit; with --json,
                       also write FILE's record re-evaluated with the current kernels there (its error, the
                       last history entry, kernel_version and command updated; evaluations and chains kept)

SIGINT/SIGTERM stop the run early; the checkpoint and result are still written. Exit status: 0 done,
1 runtime error (e.g. unreadable checkpoint), 2 bad arguments.
)";

const char* kMergeHelp = R"(usage: warpcheck merge FILE... [--json OUT]

Combines files of one kind, told apart by their content, and writes the JSON to OUT (atomically) or stdout:

  worst-case search results or checkpoints of one search (shards of 'warpcheck worst-case --shard', separate
    runs): the worst case over all of them, the sums of evaluations, chains and seconds;
  battery results of 'warpcheck validate --shard I/N --json FILE', all N shards of one run: the run's results
    in its case order, equal bit for bit to an unsharded run's, with the correction (Holm or Sidak) recomputed
    over all of them; 'warpcheck report --from OUT' reads it. Refused, naming the files: a shard that did not
    finish, two files with the same shard or case, a missing shard, or shards that differ in --samples,
    --seed, --alpha, --correction or case selection.

Exit status: 0 done (whatever the merged battery's verdicts), 1 unreadable or mismatched files, 2 bad arguments.
)";

// The signal handler can only reach a flag with static storage; this is the CLI process's one such flag.
std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop.store(true); }

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot read " + path);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

bool file_exists(const std::string& path) { return static_cast<bool>(std::ifstream(path)); }

void list_searches() {
  for (const Search& s : all_searches()) {
    std::printf("%s\n  %s\n", s.name.c_str(), s.description.c_str());
    if (!s.paper.empty()) std::printf("  paper: %s\n", s.paper.c_str());
    for (const auto& p : s.parameters)
      std::printf("    %-28s [%Lg, %Lg]  %s\n", p.name.c_str(), p.lo, p.hi, p.meaning.c_str());
  }
}

std::string joined(const char* head, const std::vector<std::string>& args) {
  std::string c = head;
  for (const auto& a : args) c += " " + a;
  return c;
}

// The command line of `warpcheck worst-case`.
struct WorstCaseOptions {
  std::string name, checkpoint, json, evaluate;
  double seconds = 60, checkpoint_every = 10, progress = 5;
  int threads = 1;
  std::uint64_t seed = 1, shard_index = 0, shard_count = 1;
  bool list = false, help = false;
};

WorstCaseOptions parse_worst_case(const std::vector<std::string>& args) {
  WorstCaseOptions o;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      return args[++i];
    };
    if (a == "--help" || a == "-h") {
      o.help = true;
      return o;
    } else if (a == "--list")
      o.list = true;
    else if (a == "--search")
      o.name = value();
    else if (a == "--seconds")
      o.seconds = parse_double(a, value(), 0, 1e9);
    else if (a == "--threads")
      o.threads = int(parse_u64(a, value(), 1, 1024));
    else if (a == "--seed")
      o.seed = parse_u64(a, value(), 0, UINT64_MAX);
    else if (a == "--checkpoint")
      o.checkpoint = value();
    else if (a == "--checkpoint-every")
      o.checkpoint_every = parse_double(a, value(), 0.1, 1e9);
    else if (a == "--progress")
      o.progress = parse_double(a, value(), 0, 1e9);
    else if (a == "--json")
      o.json = value();
    else if (a == "--evaluate")
      o.evaluate = value();
    else if (a == "--shard")
      parse_shard(value(), o.shard_index, o.shard_count);
    else
      throw UsageError("unknown option '" + a + "'");
  }
  return o;
}

// --evaluate FILE: the search's objective at the input a record holds (of this search or one with the same
// parameters), printed and, with --json, written as a record of this search.
int evaluate_record(const Search& search, const WorstCaseOptions& o, const std::vector<std::string>& args) {
  SearchRecord r;
  try {
    r = record_from_json(read_file(o.evaluate));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "warpcheck worst-case: %s: %s\n", o.evaluate.c_str(), e.what());
    return 1;
  }
  const std::optional<Search> from = find_search(r.search);
  bool same = from && from->parameters.size() == search.parameters.size();
  for (std::size_t i = 0; same && i < search.parameters.size(); ++i)
    same = from->parameters[i].name == search.parameters[i].name;
  if (!same)
    throw UsageError(o.evaluate + " holds an input of '" + r.search + "', whose parameters differ from '" + o.name +
                     "'s");
  if (r.best_x.empty()) throw UsageError(o.evaluate + " holds no input");
  const long double value = search.objective(r.best_x);
  std::printf("%s at the input of %s: %.6Le\n", o.name.c_str(), o.evaluate.c_str(), value);
  if (!o.json.empty()) {
    r.search = o.name;
    r.best_f = value;
    if (!r.history.empty()) r.history.back().best_f = value;
    r.kernel_version = source_version();
    r.command = joined("warpcheck worst-case", args);
    write_file_atomically(o.json, to_json(r, &search));
  }
  return 0;
}

// The record a run starts from: its checkpoint when one exists (it must be of the same search, seed and shard),
// else an empty record. Empty optional: the checkpoint could not be read (reported).
std::optional<SearchRecord> starting_record(const WorstCaseOptions& o) {
  SearchRecord state;
  state.search = o.name, state.seed = o.seed, state.shard_index = o.shard_index, state.shard_count = o.shard_count;
  if (o.checkpoint.empty() || !file_exists(o.checkpoint)) return state;
  try {
    state = record_from_json(read_file(o.checkpoint));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "warpcheck worst-case: checkpoint %s: %s\n", o.checkpoint.c_str(), e.what());
    return std::nullopt;
  }
  if (state.search != o.name || state.seed != o.seed || state.shard_index != o.shard_index ||
      state.shard_count != o.shard_count)
    throw UsageError("checkpoint " + o.checkpoint + " belongs to search '" + state.search + "' seed " +
                     std::to_string(state.seed) + " shard " + std::to_string(state.shard_index) + "/" +
                     std::to_string(state.shard_count) + ", not to this command");
  std::fprintf(stderr, "resuming from %s: %.1f s, %llu chains, best %.3Le\n", o.checkpoint.c_str(), state.seconds,
               (unsigned long long)state.chains, state.best_f);
  return state;
}

// The search's run: a checkpoint periodically and at the next tick (0.25 s) after every improvement of the best
// so far, progress on stderr, the record to --json (or stdout) at the end.
int run_worst_case(const Search& search, const WorstCaseOptions& w, SearchRecord& state) {
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  RunOptions o;
  o.seconds = w.seconds;
  o.threads = w.threads;
  o.stop = &g_stop;
  o.tick_seconds = 0.25;
  double last_checkpoint = state.seconds, last_progress = state.seconds;
  std::size_t checkpointed_improvements = state.history.size();
  o.tick = [&](const SearchRecord& snap, double rate) {
    if (!w.checkpoint.empty() &&
        (snap.seconds - last_checkpoint >= w.checkpoint_every || snap.history.size() != checkpointed_improvements)) {
      write_file_atomically(w.checkpoint, to_json(snap, &search));
      last_checkpoint = snap.seconds;
      checkpointed_improvements = snap.history.size();
    }
    if (w.progress > 0 && snap.seconds - last_progress >= w.progress) {
      std::fprintf(stderr, "[%s %llu/%llu] %.0f/%.0f s  chains %llu  evals %lld (%.3g/s)  best %.4Le\n", w.name.c_str(),
                   (unsigned long long)snap.shard_index, (unsigned long long)snap.shard_count, snap.seconds, w.seconds,
                   (unsigned long long)snap.chains, snap.evaluations, rate, snap.best_f);
      last_progress = snap.seconds;
    }
  };
  try {
    run_search(search, state, o);
    const std::string text = to_json(state, &search);
    if (!w.checkpoint.empty()) write_file_atomically(w.checkpoint, text);
    if (w.json.empty())
      std::fputs(text.c_str(), stdout);
    else
      write_file_atomically(w.json, text);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "warpcheck worst-case: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int worst_case_main(const std::vector<std::string>& args) {
  const WorstCaseOptions o = parse_worst_case(args);
  if (o.help) {
    std::fputs(kWorstCaseHelp, stdout);
    return 0;
  }
  if (o.list) {
    list_searches();
    return 0;
  }
  if (o.name.empty()) throw UsageError("--search NAME is required (see --list)");
  const std::optional<Search> search = find_search(o.name);
  if (!search) throw UsageError("unknown search '" + o.name + "' (see --list)");
  if (!o.evaluate.empty()) return evaluate_record(*search, o, args);
  std::optional<SearchRecord> state = starting_record(o);
  if (!state) return 1;
  state->kernel_version = source_version();
  state->command = joined("warpcheck worst-case", args);
  state->target_seconds = o.seconds;
  return run_worst_case(*search, o, *state);
}

int merge_main(const std::vector<std::string>& args) {
  std::vector<std::string> files;
  std::string json;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kMergeHelp, stdout);
      return 0;
    } else if (args[i] == "--json") {
      if (i + 1 >= args.size()) throw UsageError("--json needs a value");
      json = args[++i];
    } else if (!args[i].empty() && args[i][0] == '-') {
      throw UsageError("unknown option '" + args[i] + "'");
    } else {
      files.push_back(args[i]);
    }
  }
  if (files.empty()) throw UsageError("no files to merge");
  try {
    std::vector<std::string> texts, battery;
    for (const auto& f : files) {
      texts.push_back(read_file(f));
      try {
        if (is_battery_results(texts.back())) battery.push_back(f);
      } catch (const std::exception& e) {
        throw std::runtime_error(f + ": " + e.what());
      }
    }
    if (battery.size() == files.size()) return merge_battery(files, texts, json);
    for (const auto& f : files)
      if (!battery.empty() && std::find(battery.begin(), battery.end(), f) == battery.end())
        throw std::runtime_error(battery.front() + " holds battery results, " + f +
                                 " does not: merge files of one kind");
    std::vector<SearchRecord> records;
    for (std::size_t i = 0; i < files.size(); ++i) {
      try {
        records.push_back(record_from_json(texts[i]));
      } catch (const std::exception& e) {
        throw std::runtime_error(files[i] + ": " + e.what());
      }
    }
    SearchRecord m = merge_records(records);
    m.merged_from = files;
    m.command = joined("warpcheck merge", args);
    const std::optional<Search> s = find_search(m.search);
    const std::string text = to_json(m, s ? &*s : nullptr);
    if (json.empty())
      std::fputs(text.c_str(), stdout);
    else
      write_file_atomically(json, text);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "warpcheck merge: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace warpcheck::cli
