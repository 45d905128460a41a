// Uploads that do not make the host wait: each goes from its own host copy, kept until the
// device has read it, into its own device buffer. The host prepares the next steps while the
// device works, and waits only when it is `slots` uploads ahead (the in-order queue keeps each
// buffer's reuse behind the commands that read it).
#pragma once

#include <utility>
#include <vector>

#include "cl/buffer.hpp"
#include "cl/event.hpp"

namespace riner::cl {

template <typename T>
class UploadRing {
 public:
  UploadRing(Context& context, std::size_t slots) : context_(context), slots_(slots) {}

  // Swaps `host` into the next slot (the caller gets an older staging vector back to refill),
  // enqueues its upload and returns the device buffer that holds it for every command
  // enqueued after this call.
  const Buffer<T>& upload(std::vector<T>& host) {
    Slot& slot = slots_[next_];
    next_ = (next_ + 1) % slots_.size();
    if (slot.done) slot.done.wait();  // the device has read this slot's previous contents
    slot.host.swap(host);
    if (slot.device.size() < slot.host.size()) {
      slot.device = Buffer<T>(context_, slot.host.size() + slot.host.size() / 4 + 1);
    }
    cl_event done = nullptr;
    slot.device.write_async(std::span<const T>(slot.host), &done);
    slot.done = Event(done);
    return slot.device;
  }

 private:
  struct Slot {
    std::vector<T> host;
    Buffer<T> device;
    Event done;
  };
  Context& context_;
  std::vector<Slot> slots_;
  std::size_t next_ = 0;
};

}  // namespace riner::cl
