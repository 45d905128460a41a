#include "riner/projector.hpp"

#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "ops/backproject.hpp"
#include "ops/project.hpp"
#include "reference/project_ref.hpp"
#include "riner/error.hpp"

namespace riner {

struct Projector::Impl {
  Geometry geometry;
  Engine engine;
  std::optional<Device> device;
  std::unique_ptr<ops::ProjectOp> project;
  std::unique_ptr<ops::BackprojectOp> backproject;
};

Projector::Projector(const Geometry& geometry, Engine engine, std::optional<Device> device)
    : impl_(std::make_unique<Impl>()) {
  geometry.validate();
  impl_->geometry = geometry;
  impl_->engine = engine;
  if (engine == Engine::kOpenCL) {
    impl_->device = device ? *device : Device::open();
    impl_->project = std::make_unique<ops::ProjectOp>(cl::context_of(*impl_->device), geometry);
    impl_->backproject =
        std::make_unique<ops::BackprojectOp>(cl::context_of(*impl_->device), geometry);
  }
}

Projector::~Projector() = default;
Projector::Projector(Projector&&) noexcept = default;
Projector& Projector::operator=(Projector&&) noexcept = default;

const Geometry& Projector::geometry() const { return impl_->geometry; }
Engine Projector::engine() const { return impl_->engine; }

Array Projector::project(const Array& volume) const {
  const Geometry& g = impl_->geometry;
  if (volume.shape != g.volume_shape) {
    throw InputError("volume has shape " + shape_string(volume.shape) +
                     " but the geometry's grid is " + shape_string(g.volume_shape));
  }
  Array out(g.measurement_shape());
  if (impl_->engine == Engine::kReference) {
    out.data = ref::project(g, volume.data);
    return out;
  }
  cl::Context& ctx = cl::context_of(*impl_->device);
  cl::Buffer<float> d_volume(ctx, std::span<const float>(volume.data));
  cl::Buffer<float> d_out(ctx, out.size());
  impl_->project->forward(d_volume, d_out);
  d_out.read(std::span<float>(out.data));
  return out;
}

Array Projector::adjoint(const Array& measurement) const {
  const Geometry& g = impl_->geometry;
  g.check_measurement_shape(measurement.shape);
  Array volume(g.volume_shape);
  if (impl_->engine == Engine::kReference) {
    volume.data = ref::backproject_adjoint(g, measurement.data);
    return volume;
  }
  cl::Context& ctx = cl::context_of(*impl_->device);
  cl::Buffer<float> d_values(ctx, std::span<const float>(measurement.data));
  cl::Buffer<float> d_volume(ctx, volume.size());
  impl_->backproject->adjoint(d_values, d_volume);
  d_volume.read(std::span<float>(volume.data));
  return volume;
}

}  // namespace riner
