#include "cl/program_builder.hpp"

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <system_error>

#include "kernels/embedded_kernels.hpp"
#include "riner/log.hpp"
#include "util/atomic_file.hpp"
#include "util/hash.hpp"

namespace riner::cl {

namespace {

constexpr char kMagic[8] = {'R', 'I', 'N', 'E', 'R', 'C', 'L', '1'};

std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::string build_log(cl_program program, cl_device_id device) {
  std::size_t size = 0;
  if (clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size) !=
      CL_SUCCESS) {
    return "(no build log)";
  }
  std::string log(size, '\0');
  clGetProgramBuildInfo(program, device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

void put_u64(std::string& out, std::uint64_t v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(v));
}

bool get_u64(std::string_view& in, std::uint64_t& v) {
  if (in.size() < sizeof(v)) return false;
  std::memcpy(&v, in.data(), sizeof(v));
  in.remove_prefix(sizeof(v));
  return true;
}

// The binary stored under `path` for exactly this key; nullopt on a miss. Corrupt entries are
// deleted.
std::optional<std::string> load_entry(const std::filesystem::path& path, const std::string& key) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  std::string content((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::string_view in(content);
  std::uint64_t key_size = 0;
  std::uint64_t bin_size = 0;
  std::uint64_t checksum = 0;
  bool ok = in.size() >= sizeof(kMagic) && std::memcmp(in.data(), kMagic, sizeof(kMagic)) == 0;
  if (ok) in.remove_prefix(sizeof(kMagic));
  ok = ok && get_u64(in, key_size) && key_size <= in.size();
  std::string_view stored_key = ok ? in.substr(0, key_size) : std::string_view();
  if (ok) in.remove_prefix(key_size);
  ok = ok && get_u64(in, bin_size) && get_u64(in, checksum) && bin_size == in.size() &&
       util::fnv1a64(in) == checksum;
  if (!ok) {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    warn("discarded a corrupt program cache entry " + path.string());
    return std::nullopt;
  }
  if (stored_key != key) return std::nullopt;  // a hash collision: rebuild and overwrite
  return std::string(in);
}

void store_entry(const std::filesystem::path& path, const std::string& key,
                 const std::string& binary) {
  std::string content(kMagic, sizeof(kMagic));
  put_u64(content, key.size());
  content += key;
  put_u64(content, binary.size());
  put_u64(content, util::fnv1a64(binary));
  content += binary;
  try {
    std::filesystem::create_directories(path.parent_path());
    util::AtomicFile out(path);
    {
      std::ofstream file(out.temp_path(), std::ios::binary);
      file.write(content.data(), static_cast<std::streamsize>(content.size()));
      if (!file.flush()) throw Error("write failed");
    }
    out.commit();
  } catch (const std::exception& e) {
    warn("could not store a program cache entry in " + path.parent_path().string() + ": " +
         e.what());
  }
}

std::string program_binary(cl_program program) {
  std::size_t size = 0;
  RINER_CL_CALL(clGetProgramInfo, program, CL_PROGRAM_BINARY_SIZES, sizeof(size), &size, nullptr);
  std::string binary(size, '\0');
  unsigned char* ptr = reinterpret_cast<unsigned char*>(binary.data());
  RINER_CL_CALL(clGetProgramInfo, program, CL_PROGRAM_BINARIES, sizeof(ptr), &ptr, nullptr);
  return binary;
}

Handle<cl_program> from_binary(cl_context context, cl_device_id device, const std::string& binary,
                               const std::string& options) {
  const unsigned char* ptr = reinterpret_cast<const unsigned char*>(binary.data());
  std::size_t size = binary.size();
  cl_int binary_status = CL_SUCCESS;
  cl_int status = CL_SUCCESS;
  cl_program program =
      clCreateProgramWithBinary(context, 1, &device, &size, &ptr, &binary_status, &status);
  if (status != CL_SUCCESS || binary_status != CL_SUCCESS) {
    if (program != nullptr) clReleaseProgram(program);
    return {};
  }
  Handle<cl_program> handle(program);
  if (clBuildProgram(program, 1, &device, options.c_str(), nullptr, nullptr) != CL_SUCCESS) {
    return {};
  }
  return handle;
}

}  // namespace

std::optional<std::filesystem::path> binary_cache_dir() {
  if (const char* dir = std::getenv("RINER_CACHE_DIR"); dir != nullptr && *dir != '\0') {
    if (std::strcmp(dir, "off") == 0) return std::nullopt;
    return std::filesystem::path(dir);
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg == '/') {
    return std::filesystem::path(xdg) / "riner";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".cache" / "riner";
  }
  return std::nullopt;
}

namespace {
std::atomic<bool> every_platform{false};
}  // namespace

bool disk_cache_serves(const std::string& platform) {
  return every_platform.load() || platform.find("Portable Computing Language") == std::string::npos;
}

void serve_every_platform_for_tests(bool on) { every_platform.store(on); }

BuiltProgram build_program(cl_context context, cl_device_id device,
                           const std::vector<std::string>& sources, const std::string& options,
                           const std::string& device_key, bool use_disk_cache) {
  std::vector<std::string> texts;
  std::string key = "riner-program-cache-v1\n" + device_key + "\n";
  for (const std::string& name : sources) {
    texts.push_back(kernels::kernel_source(name));
    key += name + ":" + hex64(util::fnv1a64(texts.back())) + ":" +
           std::to_string(texts.back().size()) + "\n";
  }
  std::string full_options = "-cl-std=CL1.2";
  if (!options.empty()) full_options += " " + options;
  if (const char* extra = std::getenv("RINER_CL_BUILD_OPTIONS"); extra != nullptr && *extra) {
    full_options += std::string(" ") + extra;
  } else {
    // A compiler's warnings reach nobody but the user's terminal (PoCL on a CPU without
    // AVX-512 prints "39 warnings generated", its own headers' float16 ABI note); a failed
    // build still shows its errors, and RINER_CL_BUILD_OPTIONS=-Werror shows the warnings.
    full_options += " -w";
  }
  key += full_options;

  std::optional<std::filesystem::path> entry;
  if (auto dir = use_disk_cache ? binary_cache_dir() : std::nullopt) {
    entry = *dir / (sources.back() + "-" + hex64(util::fnv1a64(key)) + ".clbin");
    if (auto binary = load_entry(*entry, key)) {
      if (Handle<cl_program> program = from_binary(context, device, *binary, full_options)) {
        return {std::move(program), true};
      }
      std::error_code ignored;
      std::filesystem::remove(*entry, ignored);  // stale for this driver: rebuild below
    }
  }

  std::vector<const char*> ptrs;
  std::vector<std::size_t> lengths;
  for (const std::string& text : texts) {
    ptrs.push_back(text.data());
    lengths.push_back(text.size());
  }
  cl_int status = CL_SUCCESS;
  cl_program raw = clCreateProgramWithSource(context, static_cast<cl_uint>(ptrs.size()),
                                             ptrs.data(), lengths.data(), &status);
  check(status, "clCreateProgramWithSource", RINER_HERE);
  Handle<cl_program> program(raw);
  status = clBuildProgram(raw, 1, &device, full_options.c_str(), nullptr, nullptr);
  if (status != CL_SUCCESS) {
    throw BuildError(status, sources.back(), full_options, build_log(raw, device), RINER_HERE);
  }
  if (entry) store_entry(*entry, key, program_binary(raw));
  return {std::move(program), false};
}

}  // namespace riner::cl
