// bench-load: time to the scene in memory (rtr::loadScene: parsed, checked, clusters built where the file
// has none) for each file given, in one run, plus the EXT_meshopt_compression decode alone (GB/s of output,
// one core and all cores) for GLB files that use it, and `assimp info` on each glTF when assimp is found.
// tools/report/collect.sh runs it on the 1M-triangle temple as OBJ, .rtrscene, GLB and meshopt GLB.
#include <sys/resource.h>
#include <sys/wait.h>
#include <spawn.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <simdjson.h>

#include "scene/binio.hpp"
#include "scene/clusters.hpp"
#include "scene/course.hpp"
#include "scene/gltf.hpp"
#include "scene/gltf_compress.hpp"
#include "scene/load.hpp"
#include "scene/obj.hpp"
#include "scene/rtrscene.hpp"
#include "core/parallel.hpp"

extern char** environ;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The file's own reader alone, without loadScene's cluster building (which .rtrscene files skip).
rtr::Scene readOnly(const fs::path& f, const rtr::LoadOptions& quiet) {
  const std::string n = lower(f.filename().string()), ext = lower(f.extension().string());
  if (ext == ".rtrscene") return rtr::loadRtrScene(f);
  if (ext == ".comp5892mesh") return rtr::loadCourseMesh(f);
  if (ext == ".gltf" || ext == ".glb") return rtr::loadGltf(f, quiet);
  rtr::ObjOptions o;
  static_cast<rtr::LoadOptions&>(o) = quiet;
  return rtr::loadObj(f, o);
}

// One compressed bufferView of a GLB: its bytes in the BIN chunk and its extension's fields.
struct MeshoptView {
  std::span<const uint8_t> src;
  size_t count = 0, stride = 0;
  std::string mode, filter;
};

// The meshopt views of a GLB whose compressed data lies in its BIN chunk (what gltfpack -cc writes).
std::vector<MeshoptView> meshoptViews(const std::vector<uint8_t>& glb) {
  std::vector<MeshoptView> views;
  auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, glb.data() + at, 4);
    return v;
  };
  if (glb.size() < 20 || std::memcmp(glb.data(), "glTF", 4) != 0) return views;
  const size_t jsonLen = u32(12), binAt = 20 + jsonLen + 8;
  if (binAt > glb.size()) return views;
  const std::span<const uint8_t> bin(glb.data() + binAt, std::min<size_t>(u32(binAt - 8), glb.size() - binAt));
  simdjson::dom::parser parser;
  simdjson::dom::element root = parser.parse(reinterpret_cast<const char*>(glb.data()) + 20, jsonLen);
  simdjson::dom::array bufferViews;
  if (root["bufferViews"].get(bufferViews)) return views;
  for (simdjson::dom::element v : bufferViews) {
    simdjson::dom::element m;
    if (v.at_pointer("/extensions/EXT_meshopt_compression").get(m)) continue;
    uint64_t buffer = 0, offset = 0, length = 0, count = 0, stride = 0;
    std::string_view mode, filter = "NONE";
    auto get = [&](const char* key, auto& out) { return m[key].get(out) == simdjson::SUCCESS; };
    if (!get("buffer", buffer) || !get("byteLength", length) || !get("count", count) || !get("byteStride", stride) ||
        !get("mode", mode))
      continue;
    if (!get("byteOffset", offset)) offset = 0;
    if (!get("filter", filter)) filter = "NONE";
    if (buffer != 0 || offset + length > bin.size()) continue;
    views.push_back({bin.subspan(offset, length), count, stride, std::string(mode), std::string(filter)});
  }
  return views;
}

// Decodes every view `runs` times on `threads` threads; returns the output GB/s of the median run.
double meshoptRate(const std::vector<MeshoptView>& views, int runs, unsigned threads, size_t& outBytes) {
  outBytes = 0;
  for (const MeshoptView& v : views) outBytes += v.count * v.stride;
  std::vector<std::vector<uint8_t>> out(views.size());
  for (size_t i = 0; i < views.size(); ++i) out[i].resize(views[i].count * views[i].stride);
  std::vector<double> times;
  for (int r = 0; r < runs; ++r) {
    const auto t = Clock::now();
    rtr::parallelFor(views.size(), threads, [&](size_t i) {
      rtr::gltf::decodeMeshopt(views[i].src, views[i].count, views[i].stride, views[i].mode, views[i].filter, out[i]);
    });
    times.push_back(since(t));
  }
  return double(outBytes) / 1e9 / median(times);
}

// `assimp info FILE`, its output dropped: wall seconds and peak memory (MB), or a negative time.
double runAssimp(const std::string& assimp, const fs::path& file, double& peakMb) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  const std::string f = file.string();
  char* argv[] = {const_cast<char*>(assimp.c_str()), const_cast<char*>("info"), const_cast<char*>(f.c_str()), nullptr};
  pid_t pid;
  const auto t = Clock::now();
  const int rc = posix_spawn(&pid, assimp.c_str(), &fa, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  int status = 0;
  rusage ru{};
  wait4(pid, &status, 0, &ru);
  const double s = since(t);
  peakMb = double(ru.ru_maxrss) / 1024.0;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? s : -1;
}

// assimp beside this executable (a bundle's bin/), else on PATH; empty: none.
std::string findAssimp() {
  std::vector<fs::path> dirs{fs::canonical("/proc/self/exe").parent_path()};
  if (const char* path = std::getenv("PATH"))
    for (std::string_view p(path); !p.empty();) {
      const size_t c = p.find(':');
      dirs.emplace_back(std::string(p.substr(0, c)));
      p = c == std::string_view::npos ? std::string_view() : p.substr(c + 1);
    }
  for (const fs::path& d : dirs)
    if (::access((d / "assimp").c_str(), X_OK) == 0) return (d / "assimp").string();
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Times loading scenes into memory (rtr::loadScene), each file in turn, in one run", "bench-load"};
  std::vector<std::string> files;
  int runs = 5;
  bool noAssimp = false;
  app.add_option("FILES", files, "scene files (.obj, .rtrscene, .gltf, .glb, ...)")->required();
  app.add_option("--runs", runs, "loads per file (the median is reported)")->check(CLI::Range(1, 1000));
  app.add_flag("--no-assimp", noAssimp, "do not time `assimp info` on the glTF files");
  CLI11_PARSE(app, argc, argv);

  rtr::LoadOptions quiet;
  quiet.warn = quiet.note = [](const std::string&) {};
  // Per run: the reader alone, then the clusters loadScene builds for formats that store none (the scene
  // in memory as rtr-view gets it is the sum).
  std::printf(
      "| file | MB | triangles | instances | read s (median, min) | + clusters s | scene in memory s | vs .rtrscene |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|\n");
  double rtrscene = 0;
  for (const std::string& f : files) {
    std::vector<double> reads, clusters, totals;
    size_t triangles = 0, instances = 0;
    try {
      for (int r = 0; r < runs; ++r) {
        auto t = Clock::now();
        rtr::Scene s = readOnly(f, quiet);
        reads.push_back(since(t));
        t = Clock::now();
        rtr::buildMissingClusters(s);
        clusters.push_back(since(t));
        totals.push_back(reads.back() + clusters.back());
        triangles = 0;
        for (const rtr::Mesh& m : s.meshes) triangles += m.triangleCount();
        instances = s.instances.size();
      }
    } catch (const std::exception& e) {
      std::printf("| %s | – | – | – | failed: %s | | | |\n", fs::path(f).filename().c_str(), e.what());
      continue;
    }
    const double mb = double(fs::file_size(f)) / 1e6, total = median(totals);
    if (lower(fs::path(f).extension().string()) == ".rtrscene" && rtrscene == 0) rtrscene = total;
    char ratio[32] = "–";
    if (rtrscene > 0) std::snprintf(ratio, sizeof ratio, "%.1f×", total / rtrscene);
    std::printf("| %s | %.2f | %zu | %zu | %.3f, %.3f | %.3f | %.3f | %s |\n", fs::path(f).filename().c_str(), mb, triangles,
                instances, median(reads), *std::min_element(reads.begin(), reads.end()), median(clusters), total, ratio);
  }
  for (const std::string& f : files) {
    if (lower(fs::path(f).extension().string()) != ".glb") continue;
    const std::vector<uint8_t> glb = rtr::readFileBytes(f);
    const auto views = meshoptViews(glb);
    if (views.empty()) continue;
    size_t bytes = 0;
    const double one = meshoptRate(views, runs, 1, bytes), all = meshoptRate(views, runs, 0, bytes);
    std::printf("\nmeshopt decode %s: %zu views, %.1f MB out: %.2f GB/s on 1 core, %.2f GB/s on %u cores\n",
                fs::path(f).filename().c_str(), views.size(), double(bytes) / 1e6, one, all,
                std::max(1u, std::thread::hardware_concurrency()));
  }
  if (noAssimp) return 0;
  const std::string assimp = findAssimp();
  for (const std::string& f : files) {
    const std::string ext = lower(fs::path(f).extension().string());
    if (ext != ".glb" && ext != ".gltf") continue;
    if (assimp.empty()) {
      std::printf("\nassimp: not found (beside bench-load or on PATH): no assimp row\n");
      break;
    }
    double peak = 0;
    const double s = runAssimp(assimp, f, peak);
    if (s < 0) std::printf("\nassimp info %s: failed (it cannot read this file)\n", fs::path(f).filename().c_str());
    else std::printf("\nassimp info %s: %.3f s, peak %.0f MB\n", fs::path(f).filename().c_str(), s, peak);
  }
  return 0;
}
