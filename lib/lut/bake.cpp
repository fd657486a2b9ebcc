#include "lut/bake.h"

#include <tbb/task_group.h>

#include <chrono>
#include <filesystem>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/folder_lock.h"
#include "io/input.h"
#include "io/sha256.h"
#include "lut/lut.h"
#include "lut/record.h"

namespace facetfit {

namespace fs = std::filesystem;

std::string source_sha256(const std::string& source) {
  if (is_builtin(source)) {
    // A built-in is defined by its name and the code that makes it: the version is in the cache key.
    return sha256_hex(source.data(), source.size());
  }
  return sha256_file(source);
}

std::string bake_cache_key(const std::string& sha256, const BakeOptions& o) {
  nlohmann::json k;
  k["facetfit_version"] = FACETFIT_VERSION;
  k["lut_format_version"] = kLutFormatVersion;
  k["record_version"] = kRecordVersion;
  k["fit_revision"] = kFitRevision;
  k["source_sha256"] = sha256;
  k["resolution"] = o.fit.resolution;
  k["smith"] = to_string(o.fit.smith);
  k["iteration_tolerance"] = o.fit.tolerance;
  k["max_iterations"] = o.fit.max_iterations;
  k["refine"] = to_string(o.fit.refine);
  k["merl_bins"] = to_string(o.fit.merl_bins);
  k["closure_fresnel"] = to_string(o.fit.closure_fresnel);
  k["tolerance"] = o.tolerance;
  k["sampling"] = o.with_sampling;
  if (o.colorspace != kRec709Space) {
    k["colorspace"] = o.colorspace;
    k["colorspace_matrix"] = matrix_text(o.from_rec709);
  }
  const std::string text = json_text(k);
  return sha256_hex(text.data(), text.size());
}

namespace {

// The cached sidecar, if it is complete, was made from the same content with the same settings, and the
// LUT beside it is the one it wrote (a LUT truncated, emptied or replaced since is baked again).
std::optional<nlohmann::json> cached_record(const fs::path& json_path, const fs::path& lut_path, const std::string& key) {
  std::error_code ec;
  if (!fs::is_regular_file(json_path, ec) || !fs::is_regular_file(lut_path, ec)) return std::nullopt;
  const nlohmann::json j = read_json_file(json_path.string());
  if (!j.is_object() || j.value("cache_key", "") != key) return std::nullopt;
  if (j.value("lut_sha256", "") != sha256_file(lut_path.string())) return std::nullopt;
  return j;
}

}  // namespace

BakeOutcome bake_material(const std::string& source, const std::string& name, const std::string& out_dir,
                          const BakeOptions& options, const Fitter& fitter) {
  BakeOutcome out;
  out.source = source;
  out.name = name;
  const auto start = std::chrono::steady_clock::now();
  const fs::path lut_path = fs::path(out_dir) / (name + ".exr"), json_path = fs::path(out_dir) / (name + ".json");
  try {
    if (const std::string problem = output_name_problem(name); !problem.empty())
      fail(source, "output name \"" + excerpt(name, 60) + "\" " + problem);
    // With a sidecar there, a hit is likely: the hash alone first (an RGL file's table costs a second to
    // make, the hash of its 0.7 MB milliseconds), the table only on a miss. Without one, the SHA-256 of a
    // 35 MB MERL table costs as much CPU as reading and fitting it: hash on one core while the other reads.
    std::string sha;
    std::optional<HalfDiffTable> table;
    if (!options.force && fs::exists(json_path)) {
      sha = source_sha256(source);
    } else {
      std::string hash_error;
      tbb::task_group hashing;
      hashing.run([&] {
        try {
          sha = source_sha256(source);
        } catch (const Error& e) {
          hash_error = e.what();
        }
      });
      try {
        table = load_table(source, options.fit.merl_bins);
      } catch (const Error&) {
        hashing.wait();
        throw;
      }
      hashing.wait();
      if (!hash_error.empty()) throw Error(hash_error);
    }
    const std::string key = bake_cache_key(sha, options);
    if (!options.force) {
      if (auto cached = cached_record(json_path, lut_path, key)) {
        out.status = BakeOutcome::Status::cached;
        out.record = std::move(*cached);
        out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return out;
      }
    }
    if (!table) table = load_table(source, options.fit.merl_bins);
    const FitResult fit = fitter.fit(*table);
    if (!fit.ok()) fail(source, "meaningless fit: " + fit.problem);
    const Lut lut = in_colorspace(make_lut(fit, fitter.quadrature(), source, sha, options.tolerance, options.with_sampling),
                                  options.colorspace, options.from_rec709);
    // The LUT and its sidecar are written as a pair: another bake of the same name into this folder (another
    // process, other settings) waits, so the two never come from different bakes.
    const FolderLock lock(out_dir);
    write_lut(lut_path.string(), lut);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    nlohmann::json& r = out.record;
    r = fit_record(source, fit, out.seconds, options.tolerance);
    r["lut"] = lut_path.filename().string();
    r["lut_sha256"] = sha256_file(lut_path.string());
    r["warnings"] = lut.meta.warnings;  // the fit's, and what the LUT clamped to its limits (clamp_to_limits)
    r["representation"] = to_string(lut.meta.representation);
    r["ndf_error_ggx"] = lut.meta.ndf_error_ggx;
    r["ndf_error_beckmann"] = lut.meta.ndf_error_beckmann;
    r["smith"] = to_string(lut.meta.smith);
    r["resolution"] = lut.meta.resolution;
    r["tolerance"] = options.tolerance;
    r["sampling"] = options.with_sampling;
    r["source_sha256"] = sha;
    r["facetfit_version"] = FACETFIT_VERSION;
    r["cache_key"] = key;
    if (lut.meta.colorspace != kRec709Space) {  // the recommended parameters in the LUT's space, as info shows them
      r["colorspace"] = lut.meta.colorspace;
      r["recommended"] = recommended_json(recommended_parameters(lut.meta), options.tolerance);
    }
    // The sidecar goes last: its presence with this key is what marks the bake complete.
    write_file_atomic(json_path.string(), json_text(r, 2) + "\n");
    out.status = BakeOutcome::Status::baked;
  } catch (const Error& e) {
    out.status = BakeOutcome::Status::failed;
    out.error = e.what();
  } catch (const std::exception& e) {
    out.status = BakeOutcome::Status::failed;
    out.error = source + ": " + e.what();
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace facetfit
