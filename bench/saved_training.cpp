#include "saved_training.hpp"

#include <fstream>
#include <iterator>
#include <string>

#include "riner/io.hpp"
#include "riner/ring_chain.hpp"

namespace riner::bench {

namespace fs = std::filesystem;

void save_training(const fs::path& dir, Reconstructor& r, const Geometry& g, const Array& reference,
                   bool simulated, const RingCorrectionConfig& rings) {
  fs::create_directories(dir);
  const ReconstructionResult result = r.result();
  SavedTraining s{g,  result.field_image, r.trained_alpha(), reference,
                  {}, r.dead_elements(),  simulated};
  // The pixels the reconstruction zeroed after its corrections (air that training skipped).
  s.keep = Array(result.image.shape, 1.0f);
  const Array chain = correct_rings_in_order(s.field, s.alpha, g, s.dead, rings).image;
  for (std::size_t p = 0; p < s.keep.size(); ++p) {
    if (result.image.data[p] == 0.0f && chain.data[p] != 0.0f) s.keep.data[p] = 0.0f;
  }
  write_array(dir / "field.npy", s.field);
  write_array(dir / "alpha.npy", s.alpha);
  write_array(dir / "reference.npy", s.reference);
  write_array(dir / "keep.npy", s.keep);
  Array dead({s.dead.size() + 1});  // a leading -1 keeps the array non-empty
  dead.data[0] = -1.0f;
  for (std::size_t i = 0; i < s.dead.size(); ++i) dead.data[i + 1] = static_cast<float>(s.dead[i]);
  write_array(dir / "dead.npy", dead);
  std::ofstream(dir / "geometry.json") << g.to_json();
  std::ofstream(dir / "kind") << (simulated ? "simulated" : "real");
}

SavedTraining load_training(const fs::path& dir) {
  SavedTraining s;
  std::ifstream geometry(dir / "geometry.json");
  s.geometry = Geometry::from_json(std::string(std::istreambuf_iterator<char>(geometry), {}));
  s.field = read_array(dir / "field.npy").array;
  s.alpha = read_array(dir / "alpha.npy").array;
  s.reference = read_array(dir / "reference.npy").array;
  s.keep = read_array(dir / "keep.npy").array;
  const Array dead = read_array(dir / "dead.npy").array;
  for (std::size_t i = 1; i < dead.size(); ++i)
    s.dead.push_back(static_cast<std::size_t>(dead.data[i]));
  std::string kind;
  std::ifstream(dir / "kind") >> kind;
  s.simulated = kind == "simulated";
  return s;
}

}  // namespace riner::bench
