// The search engine (searches.h): the list of all searches, the threaded multi-start driver, merging shards and
// the record format. The searches themselves: polygon.cpp, kernels.cpp, caps.cpp.
#include "warpcheck/validation/searches.h"

#include <algorithm>
#include <boost/json.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

namespace warpcheck::validation {

using L = long double;
// ---- Search ---------------------------------------------------------------------------------------------

Bounds<L> Search::bounds() const {
  Bounds<L> b;
  for (const auto& p : parameters) b.lo.push_back(p.lo), b.hi.push_back(p.hi);
  return b;
}

MultiStartOptions<L> Search::options() const {
  MultiStartOptions<L> o;
  o.local.goal = Goal::kMaximize;
  o.local.max_iterations = local_iterations;
  return o;
}

std::vector<Search> all_searches() {
  std::vector<Search> v;
  append_polygon_searches(v);
  append_kernel_searches(v);
  append_cap_searches(v);
  return v;
}

std::optional<Search> find_search(const std::string& name) {
  for (auto& s : all_searches())
    if (s.name == name) return s;
  return std::nullopt;
}

// ---- The driver ---------------------------------------------------------------------------------------------

void run_search(const Search& s, SearchRecord& st, const RunOptions& o) {
  using clock = std::chrono::steady_clock;
  const Bounds<L> box = s.bounds();
  const MultiStartOptions<L> opt = s.options();
  std::mutex m;
  std::set<std::uint64_t> done(st.done_above.begin(), st.done_above.end());
  std::uint64_t cursor = st.next_local;
  const auto start = clock::now();
  const double base_seconds = st.seconds;
  const long long base_evaluations = st.evaluations;
  auto elapsed = [&] { return base_seconds + std::chrono::duration<double>(clock::now() - start).count(); };
  auto stopped = [&] { return elapsed() >= o.seconds || (o.stop && o.stop->load()); };
  if (stopped()) return;

  auto worker = [&] {
    for (;;) {
      std::uint64_t j;
      {
        std::lock_guard<std::mutex> lock(m);
        if (stopped()) return;
        while (done.count(cursor)) ++cursor;
        j = cursor++;
      }
      const ChainResult<L> r = run_chain(s.objective, box, opt, st.seed, st.global_chain(j));
      std::lock_guard<std::mutex> lock(m);
      st.evaluations += r.evaluations;
      ++st.chains;
      if (!r.x.empty() && (st.best_x.empty() || better(r.f, st.best_f, Goal::kMaximize))) {
        st.best_x = r.x, st.best_f = r.f, st.best_chain = st.global_chain(j);
        st.history.push_back({elapsed(), st.evaluations, st.chains, r.f, st.best_chain, st.shard_index});
      }
      done.insert(j);
      while (done.count(st.next_local)) done.erase(st.next_local++);
    }
  };
  std::atomic<int> running{std::max(1, o.threads)};
  std::vector<std::thread> pool;
  for (int t = 0; t < std::max(1, o.threads); ++t)
    pool.emplace_back([&] {
      worker();
      --running;
    });
  auto snapshot = [&] {
    std::lock_guard<std::mutex> lock(m);
    st.seconds = elapsed();
    st.done_above.assign(done.begin(), done.end());
    return st;
  };
  auto last_tick = clock::now();
  while (running.load() > 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (o.tick && std::chrono::duration<double>(clock::now() - last_tick).count() >= o.tick_seconds) {
      last_tick = clock::now();
      const SearchRecord snap = snapshot();
      o.tick(snap, double(snap.evaluations - base_evaluations) / std::max(1e-9, snap.seconds - base_seconds));
    }
  }
  for (auto& t : pool) t.join();
  const SearchRecord snap = snapshot();
  if (o.tick) o.tick(snap, double(snap.evaluations - base_evaluations) / std::max(1e-9, snap.seconds - base_seconds));
}

SearchRecord merge_records(const std::vector<SearchRecord>& records) {
  if (records.empty()) throw std::runtime_error("nothing to merge");
  SearchRecord out = records[0];
  out.merged_from.clear();
  out.done_above.clear();
  out.evaluations = 0, out.chains = 0, out.seconds = 0, out.target_seconds = 0;
  out.history.clear();
  std::vector<HistoryPoint> all;
  for (const auto& r : records) {
    if (r.search != out.search)
      throw std::runtime_error("cannot merge searches '" + out.search + "' and '" + r.search + "'");
    all.insert(all.end(), r.history.begin(), r.history.end());
    out.evaluations += r.evaluations, out.chains += r.chains, out.seconds += r.seconds;
    out.target_seconds += r.target_seconds;
    if (!r.best_x.empty() && (out.best_x.empty() || better(r.best_f, out.best_f, Goal::kMaximize))) {
      out.best_x = r.best_x, out.best_f = r.best_f, out.best_chain = r.best_chain;
      out.seed = r.seed, out.shard_index = r.shard_index, out.shard_count = r.shard_count;
      out.kernel_version = r.kernel_version;
    }
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const HistoryPoint& a, const HistoryPoint& b) { return a.seconds < b.seconds; });
  for (const HistoryPoint& h : all)
    if (out.history.empty() || better(h.best_f, out.history.back().best_f, Goal::kMaximize)) out.history.push_back(h);
  return out;
}

std::string source_version() {
  const std::string cmd = std::string("git -C '") + WARPCHECK_SOURCE_DIR + "' describe --always --dirty 2>/dev/null";
  std::string out;
  if (std::FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out.empty() ? "unknown" : out;
}

// ---- JSON ------------------------------------------------------------------------------------------------

std::string hex(L v) {
  char b[64];
  std::snprintf(b, sizeof b, "%La", v);
  return b;
}

L from_hex(const std::string& s) {
  char* end = nullptr;
  const L v = std::strtold(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size()) throw std::runtime_error("not a number: '" + s + "'");
  return v;
}

namespace {

std::string decimal(L v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.6Lg", v);
  return b;
}

// Boost.JSON 1.81 has no pretty printer; this one indents objects and keeps short arrays on one line.
void pretty(const boost::json::value& v, std::string& out, int indent) {
  const std::string pad(indent, ' ');
  if (v.is_object()) {
    const auto& o = v.as_object();
    if (o.empty()) return void(out += "{}");
    out += "{\n";
    std::size_t i = 0;
    for (const auto& kv : o) {
      out += pad + "  " + boost::json::serialize(boost::json::value(kv.key())) + ": ";
      pretty(kv.value(), out, indent + 2);
      out += ++i < o.size() ? ",\n" : "\n";
    }
    out += pad + "}";
  } else if (v.is_array()) {
    const auto& a = v.as_array();
    bool flat = true;
    for (const auto& e : a) flat = flat && !e.is_object() && !e.is_array();
    bool rows = !a.empty();  // an array of objects with scalar members (the history): one object per line
    for (const auto& e : a) {
      rows = rows && e.is_object();
      if (rows)
        for (const auto& kv : e.as_object()) rows = rows && !kv.value().is_object() && !kv.value().is_array();
    }
    if (rows) {
      out += "[\n";
      for (std::size_t i = 0; i < a.size(); ++i)
        out += pad + "  " + boost::json::serialize(a[i]) + (i + 1 < a.size() ? ",\n" : "\n");
      return void(out += pad + "]");
    }
    if (flat) return void(out += boost::json::serialize(v));
    out += "[\n";
    for (std::size_t i = 0; i < a.size(); ++i) {
      out += pad + "  ";
      pretty(a[i], out, indent + 2);
      out += i + 1 < a.size() ? ",\n" : "\n";
    }
    out += pad + "]";
  } else {
    out += boost::json::serialize(v);
  }
}

}  // namespace

std::string to_json(const SearchRecord& r, const Search* s) {
  boost::json::object o;
  o["search"] = r.search;
  if (s) {
    o["description"] = s->description;
    o["paper"] = s->paper;
  }
  o["kernel_version"] = r.kernel_version;
  o["command"] = r.command;
  o["seed"] = r.seed;
  o["shard"] = boost::json::array{r.shard_index, r.shard_count};
  o["worst_error"] = r.best_x.empty() ? boost::json::value(nullptr) : boost::json::value(double(r.best_f));
  o["worst_error_hex"] = hex(r.best_f);
  boost::json::array in;
  for (std::size_t i = 0; i < r.best_x.size(); ++i) {
    boost::json::object p;
    std::string name = "x";  // (not "x" + to_string: GCC 12 warns falsely, -Wrestrict)
    name += std::to_string(i);
    p["name"] = s && i < s->parameters.size() ? s->parameters[i].name : name;
    p["value"] = decimal(r.best_x[i]);
    p["hex"] = hex(r.best_x[i]);
    if (s && i < s->parameters.size()) {
      p["box"] = boost::json::array{double(s->parameters[i].lo), double(s->parameters[i].hi)};
      p["meaning"] = s->parameters[i].meaning;
    }
    in.push_back(std::move(p));
  }
  o["input"] = std::move(in);
  o["best_chain"] = r.best_chain;
  o["evaluations"] = r.evaluations;
  o["chains"] = r.chains;
  o["seconds"] = r.seconds;
  o["target_seconds"] = r.target_seconds;
  o["next_local_chain"] = r.next_local;
  boost::json::array above;
  for (auto j : r.done_above) above.push_back(j);
  o["done_local_chains_above"] = std::move(above);
  boost::json::array history;
  for (const HistoryPoint& h : r.history) {
    boost::json::object p;
    p["seconds"] = h.seconds;
    p["evaluations"] = h.evaluations;
    p["chains"] = h.chains;
    p["worst_error"] = double(h.best_f);
    p["worst_error_hex"] = hex(h.best_f);
    p["chain"] = h.chain;
    p["shard"] = h.shard_index;
    history.push_back(std::move(p));
  }
  o["history"] = std::move(history);
  if (!r.merged_from.empty()) {
    boost::json::array from;
    for (const auto& f : r.merged_from) from.push_back(boost::json::value(f));
    o["merged_from"] = std::move(from);
  }
  std::string out;
  pretty(o, out, 0);
  return out + "\n";
}

SearchRecord record_from_json(const std::string& text) {
  boost::json::error_code ec;
  const boost::json::value v = boost::json::parse(text, ec);
  if (ec || !v.is_object()) throw std::runtime_error("not a JSON object: " + ec.message());
  const auto& o = v.as_object();
  auto need = [&](const char* key) -> const boost::json::value& {
    const auto* p = o.if_contains(key);
    if (!p) throw std::runtime_error(std::string("missing field '") + key + "'");
    return *p;
  };
  auto u64 = [&](const boost::json::value& x) { return boost::json::value_to<std::uint64_t>(x); };
  SearchRecord r;
  try {
    r.search = boost::json::value_to<std::string>(need("search"));
    r.kernel_version = boost::json::value_to<std::string>(need("kernel_version"));
    r.command = boost::json::value_to<std::string>(need("command"));
    r.seed = u64(need("seed"));
    const auto& sh = need("shard").as_array();
    r.shard_index = u64(sh.at(0)), r.shard_count = u64(sh.at(1));
    for (const auto& p : need("input").as_array())
      r.best_x.push_back(from_hex(boost::json::value_to<std::string>(p.as_object().at("hex"))));
    r.best_f = from_hex(boost::json::value_to<std::string>(need("worst_error_hex")));
    r.best_chain = u64(need("best_chain"));
    r.evaluations = boost::json::value_to<long long>(need("evaluations"));
    r.chains = u64(need("chains"));
    r.seconds = boost::json::value_to<double>(need("seconds"));
    r.target_seconds = boost::json::value_to<double>(need("target_seconds"));
    r.next_local = u64(need("next_local_chain"));
    for (const auto& j : need("done_local_chains_above").as_array()) r.done_above.push_back(u64(j));
    if (const auto* h = o.if_contains("history"))  // optional: records written before it existed have none
      for (const auto& x : h->as_array()) {
        const auto& p = x.as_object();
        HistoryPoint q;
        q.seconds = boost::json::value_to<double>(p.at("seconds"));
        q.evaluations = boost::json::value_to<long long>(p.at("evaluations"));
        q.chains = u64(p.at("chains"));
        q.best_f = from_hex(boost::json::value_to<std::string>(p.at("worst_error_hex")));
        q.chain = u64(p.at("chain"));
        q.shard_index = u64(p.at("shard"));
        r.history.push_back(q);
      }
    if (const auto* f = o.if_contains("merged_from"))
      for (const auto& x : f->as_array()) r.merged_from.push_back(boost::json::value_to<std::string>(x));
  } catch (const std::runtime_error&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("malformed record: ") + e.what());
  }
  if (r.shard_count == 0 || r.shard_index >= r.shard_count) throw std::runtime_error("malformed record: bad shard");
  return r;
}

}  // namespace warpcheck::validation
