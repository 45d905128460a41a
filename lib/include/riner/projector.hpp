// The ray-driven forward projector (Joseph's method) and its exact adjoint, for any geometry:
// used to simulate scans and in tests. It is independent of Riner's point sampler, so a
// simulated scan does not flatter the reconstruction.
#pragma once

#include <memory>
#include <optional>

#include "riner/array.hpp"
#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/geometry.hpp"

namespace riner {

class Projector {
 public:
  // The OpenCL engine runs on `device` (default: Device::open()).
  Projector(const Geometry& geometry, Engine engine = Engine::kOpenCL,
            std::optional<Device> device = std::nullopt);
  ~Projector();
  Projector(Projector&&) noexcept;
  Projector& operator=(Projector&&) noexcept;

  // volume [n_y, n_x] or [n_z, n_y, n_x] (mu, 1/mm) -> measurement (line integrals).
  Array project(const Array& volume) const;
  // measurement -> volume, the exact transpose of project().
  Array adjoint(const Array& measurement) const;

  const Geometry& geometry() const;
  Engine engine() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace riner
