// Bake throughput, ours vs a tinyobjloader baseline, on the scaled temple (tools/scenegen --scale).
// Input: $RTR_BENCH_OBJ (a plain .obj; a .obj.zst beside it is used for the zstd case), default
// build/.../bench/temple/temple.obj made by the bench_bake_data target. Numbers: docs/bench/bake.md.
#include <cstdlib>
#include <filesystem>

#include <benchmark/benchmark.h>

#include "bake.hpp"
#include "baseline.hpp"
#include "core/parallel.hpp"
#include "scene/binio.hpp"
#include "scene/obj.hpp"
#include "scene/rtrscene.hpp"

namespace fs = std::filesystem;

namespace {

fs::path input(bool zstd) {
  const char* env = std::getenv("RTR_BENCH_OBJ");
  fs::path p = env ? fs::path(env) : fs::path(RTR_BENCH_DEFAULT_OBJ);
  if (zstd) p += ".zst";
  return p;
}

size_t vertices(const rtr::Scene& s) {
  size_t n = 0;
  for (const auto& m : s.meshes) n += m.positions.size();
  return n;
}

void counters(benchmark::State& st, double textBytes, double verts) {
  st.counters["MB/s"] = benchmark::Counter(textBytes / 1e6, benchmark::Counter::kIsIterationInvariantRate);
  st.counters["Mvert/s"] = benchmark::Counter(verts / 1e6, benchmark::Counter::kIsIterationInvariantRate);
  st.counters["vertices"] = verts;
}

void oursBake(benchmark::State& st, bool zstd) {
  const fs::path out = fs::temp_directory_path() / "rtr_bench_ours.rtrscene";
  rtr::BakeReport r;
  double parse = 0, weld = 0, write = 0;
  for (auto _ : st) {
    rtr::BakeOptions o{input(zstd), out, true};
    o.warn = [](const std::string&) {};
    r = rtr::bake(o);
    parse += r.parseSeconds, weld += r.weldSeconds, write += r.writeSeconds;
  }
  const double n = double(st.iterations());
  counters(st, double(r.obj.textBytes), double(r.obj.verticesAfterWeld));
  st.counters["parse_MB/s"] = double(r.obj.textBytes) / 1e6 / (parse / n);
  st.counters["weld_Mvert/s"] = double(r.obj.verticesBeforeWeld) / 1e6 / (weld / n);
  st.counters["write_MB/s"] = double(r.outputBytes) / 1e6 / (write / n);
  fs::remove(out);
}

void BM_OursBake(benchmark::State& st) { oursBake(st, false); }
void BM_OursBakeZstd(benchmark::State& st) { oursBake(st, true); }

// The OBJ parse and weld alone on 1, 2, 4, … threads up to all cores: their rates against the thread count
// (the zstd case: the .obj.zst beside it, its frames decoded on the same threads).
void oursParse(benchmark::State& st, bool zstd) {
  rtr::ObjOptions o;
  o.threads = unsigned(st.range(0));
  o.warn = [](const std::string&) {};
  rtr::ObjStats stats;
  double parse = 0, weld = 0;
  for (auto _ : st) {
    rtr::Scene s = rtr::loadObj(input(zstd), o, &stats);
    parse += stats.parseSeconds, weld += stats.weldSeconds;
  }
  const double n = double(st.iterations());
  st.counters["threads"] = double(o.threads);
  st.counters["parse_MB/s"] = double(stats.textBytes) / 1e6 / (parse / n);
  st.counters["text_MB"] = double(stats.textBytes) / 1e6;
  st.counters["weld_ms"] = weld / n * 1e3;
  st.counters["weld_Mcorner/s"] = double(stats.verticesBeforeWeld) / 1e6 / (weld / n);
}
void BM_OursParse(benchmark::State& st) { oursParse(st, false); }
void BM_OursParseZstd(benchmark::State& st) { oursParse(st, true); }

void threadCounts(benchmark::internal::Benchmark* b) {
  const unsigned all = rtr::threadCount();
  for (unsigned t = 1; t < all; t *= 2) b->Arg(t);
  b->Arg(all);
}

void BM_BaselineBake(benchmark::State& st) {
  const fs::path out = fs::temp_directory_path() / "rtr_bench_base.rtrscene";
  size_t verts = 0;
  for (auto _ : st) {
    rtr::Scene s = bench::baselineLoad(input(false));
    rtr::writeFileAtomic(out, rtr::encodeRtrScene(s));
    verts = vertices(s);
  }
  counters(st, double(fs::file_size(input(false))), double(verts));
  fs::remove(out);
}

}  // namespace

BENCHMARK(BM_OursBake)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_OursBakeZstd)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_OursParse)->Apply(threadCounts)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_OursParseZstd)->Apply(threadCounts)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_BaselineBake)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK_MAIN();
