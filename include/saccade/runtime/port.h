#pragma once
// Typed ports of a component. An Output<T> wraps a Signal<T>; Emit delivers to every
// connected input at once (or at the start of the next step for a delayed connection). An
// Input<T> keeps the latest message and whether a new one arrived since its component's last
// Step. Both know their message type's name, so that the pipeline loader checks connections.

#include <chrono>
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/runtime/bus.h"
#include "saccade/runtime/message.h"

namespace saccade::runtime {

/// Emissions held back while the components of one step's level run at the same time
/// (scheduler.cc): on a thread that has one installed, Output::Emit queues the delivery
/// instead of making it, and the scheduler delivers every component's queue after the level,
/// in execution order. So a parallel step delivers what the serial one does, in the same
/// order, bit for bit.
class DeferredEmits {
 public:
  /// This thread's queue; nullptr (deliver at once) unless the scheduler installed one.
  static DeferredEmits*& Current() {
    thread_local DeferredEmits* current = nullptr;
    return current;
  }
  void Add(std::function<void()> deliver) { pending_.push_back(std::move(deliver)); }
  /// Makes the held deliveries, in the order they were emitted.
  void Deliver() {
    for (const auto& deliver : pending_) deliver();
    pending_.clear();
  }

 private:
  std::vector<std::function<void()>> pending_;
};

/// A port's name and message type, without the type.
class PortBase {
 public:
  PortBase(std::string name, std::string message_type)
      : name_(std::move(name)), message_type_(std::move(message_type)) {}
  virtual ~PortBase() = default;
  PortBase(const PortBase&) = delete;
  PortBase& operator=(const PortBase&) = delete;

  const std::string& name() const { return name_; }
  /// MessageTraits<T>::kName of the port's message type.
  const std::string& message_type() const { return message_type_; }

 private:
  std::string name_;
  std::string message_type_;
};

/// An output without its type: lets type-erased code (the server) tap it as JSON.
class OutputBase : public PortBase {
 public:
  using PortBase::PortBase;
  /// Subscribes `slot` to every message, converted to JSON (for text links only: it costs a
  /// conversion per message).
  virtual ConnectionId ConnectJson(std::function<void(const nlohmann::json&)> slot) = 0;
  /// Removes a subscription (ConnectJson's, or the typed signal's); false when not connected.
  /// Not while the output may emit (between steps, on the pipeline's thread).
  virtual bool Disconnect(ConnectionId id) = 0;
  virtual std::size_t subscriber_count() const = 0;
};

/// Receives messages of an output; `delay` 0 delivers at once, 1 at the start of the next step.
/// `on_delivery(seconds)` is told how long each delivery took (the scheduler's overhead).
class InputBase : public PortBase {
 public:
  InputBase(std::string name, std::string message_type, bool required)
      : PortBase(std::move(name), std::move(message_type)), required_(required) {}

  bool required() const { return required_; }
  bool connected() const { return connected_; }
  /// A message arrived since the component's last Step.
  bool fresh() const { return fresh_; }
  /// At least one message arrived since Start.
  virtual bool has_value() const = 0;

  /// Connects this input to `output`. Throws InvalidArgument when the message types differ
  /// or the input is already connected.
  virtual void ConnectFrom(OutputBase& output, int delay,
                           std::function<void(double)> on_delivery) = 0;
  /// Hands over a message held back by a delayed connection (scheduler, start of a step).
  virtual void DeliverDelayed() = 0;
  /// Marks the latest message as seen (scheduler, after the component's Step).
  void MarkSeen() { fresh_ = false; }

 protected:
  bool fresh_ = false;
  bool connected_ = false;

 private:
  bool required_;
};

/// A typed output port.
template <Message T>
class Output final : public OutputBase {
 public:
  explicit Output(std::string name)
      : OutputBase(name, MessageName<T>()), signal_(std::move(name)) {}

  /// Sends `message` to every connected input (by reference; see Signal::Emit).
  void Emit(const T& message) const {
    if (DeferredEmits* deferred = DeferredEmits::Current()) {
      deferred->Add([this, message] { signal_.Emit(message); });
      return;
    }
    signal_.Emit(message);
  }
  Signal<T>& signal() { return signal_; }

  ConnectionId ConnectJson(std::function<void(const nlohmann::json&)> slot) override {
    return signal_.Connect(
        [slot = std::move(slot)](const T& message) { slot(MessageTraits<T>::ToJson(message)); });
  }
  bool Disconnect(ConnectionId id) override { return signal_.Disconnect(id); }
  std::size_t subscriber_count() const override { return signal_.subscriber_count(); }

 private:
  Signal<T> signal_;
};

/// A typed input port: the latest message, and whether it is new since the last Step.
template <Message T>
class Input final : public InputBase {
 public:
  Input(std::string name, bool required) : InputBase(std::move(name), MessageName<T>(), required) {}

  bool has_value() const override { return latest_.has_value(); }
  /// The latest message. Throws saccade::Error when none has arrived yet.
  const T& value() const {
    if (!latest_) throw Error("input '" + name() + "': no message has arrived yet");
    return *latest_;
  }
  /// The latest message, or nullptr.
  const T* get() const { return latest_ ? &*latest_ : nullptr; }

  /// Delivers a message directly (tests, or components wired by hand).
  void Deliver(const T& message) {
    latest_ = message;
    fresh_ = true;
  }

  void ConnectFrom(OutputBase& output, int delay, std::function<void(double)> on_delivery) override;
  void DeliverDelayed() override {
    if (!pending_) return;
    latest_ = std::move(*pending_);
    pending_.reset();
    fresh_ = true;
  }

 private:
  std::optional<T> latest_;
  std::optional<T> pending_;  // held back by a delayed connection until the next step
};

// ---- implementation ----------------------------------------------------------------------

template <Message T>
void Input<T>::ConnectFrom(OutputBase& output, int delay, std::function<void(double)> on_delivery) {
  if (connected_) throw InvalidArgument("input '" + name() + "' is already connected");
  auto* typed = dynamic_cast<Output<T>*>(&output);
  if (typed == nullptr) {
    throw InvalidArgument("output '" + output.name() + "' sends " + output.message_type() +
                          ", input '" + name() + "' expects " + message_type());
  }
  if (delay != 0 && delay != 1) {
    throw InvalidArgument("input '" + name() + "': delay must be 0 or 1");
  }
  typed->signal().Connect([this, delay, on_delivery = std::move(on_delivery)](const T& message) {
    // Timed so that the scheduler can report the bus's share of the loop.
    const auto start = std::chrono::steady_clock::now();
    if (delay == 0) {
      Deliver(message);
    } else {
      pending_ = message;
    }
    if (on_delivery) {
      on_delivery(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  });
  connected_ = true;
}

}  // namespace saccade::runtime
