#pragma once
// The in-process bus (seed section 5.4): signals (one-to-many, no reply) and methods
// (one-to-one, with a reply or an error). Messages are passed by const reference and never
// serialised; images inside messages are std::shared_ptr<const Image>, so every subscriber
// sees the same pixels (DESIGN.md: images move by shared ownership, never by copy).
//
// Thread-safety: none. Connect and Bind at configuration time, then Emit and Call from the
// thread that runs the pipeline.

#include <cstddef>
#include <exception>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::runtime {

/// A method call that failed: no handler bound, a second handler bound, or the handler threw.
/// The message starts with "method '<name>': ".
class MethodError : public Error {
 public:
  MethodError(const std::string& method, const std::string& what)
      : Error("method '" + method + "': " + what), method_(method) {}
  const std::string& method() const { return method_; }

 private:
  std::string method_;
};

/// Identifies one subscription of a Signal; never 0.
using ConnectionId = std::size_t;

/// One-to-many notification: Emit calls every subscriber in connection order; no reply.
template <typename T>
class Signal {
 public:
  using Slot = std::function<void(const T&)>;

  explicit Signal(std::string name = {}) : name_(std::move(name)) {}

  const std::string& name() const { return name_; }

  /// Subscribes `slot`; returns its id. Throws InvalidArgument for an empty slot.
  ConnectionId Connect(Slot slot) {
    if (!slot) throw InvalidArgument("Signal::Connect: signal '" + name_ + "': empty slot");
    slots_.emplace_back(next_id_, std::move(slot));
    return next_id_++;
  }

  /// Removes a subscription; false when `id` is not connected.
  bool Disconnect(ConnectionId id) {
    for (auto it = slots_.begin(); it != slots_.end(); ++it) {
      if (it->first == id) {
        slots_.erase(it);
        return true;
      }
    }
    return false;
  }

  /// Calls every subscriber with the same `message` (by reference), in connection order.
  /// A subscriber's exception propagates to the caller; later subscribers are not called.
  void Emit(const T& message) const {
    for (const auto& [id, slot] : slots_) slot(message);
  }

  std::size_t subscriber_count() const { return slots_.size(); }

 private:
  std::string name_;
  std::vector<std::pair<ConnectionId, Slot>> slots_;
  ConnectionId next_id_ = 1;
};

/// One-to-one request with a reply: exactly one handler may be bound.
template <typename Request, typename Reply>
class Method {
 public:
  using Handler = std::function<Reply(const Request&)>;

  explicit Method(std::string name) : name_(std::move(name)) {}

  const std::string& name() const { return name_; }
  bool bound() const { return static_cast<bool>(handler_); }

  /// Binds the handler. Throws MethodError when one is already bound, InvalidArgument for
  /// an empty handler.
  void Bind(Handler handler) {
    if (!handler) throw InvalidArgument("Method::Bind: method '" + name_ + "': empty handler");
    if (handler_) throw MethodError(name_, "a handler is already bound (methods are one-to-one)");
    handler_ = std::move(handler);
  }

  /// Removes the handler (if any), so that another may be bound.
  void Unbind() { handler_ = nullptr; }

  /// Calls the handler and returns its reply. Throws MethodError when no handler is bound,
  /// or when the handler throws (the message carries the handler's).
  Reply Call(const Request& request) const {
    if (!handler_) throw MethodError(name_, "no handler bound");
    try {
      return handler_(request);
    } catch (const MethodError&) {
      throw;
    } catch (const std::exception& error) {
      throw MethodError(name_, std::string("handler failed: ") + error.what());
    } catch (...) {
      throw MethodError(name_, "handler failed with an unknown exception");
    }
  }

 private:
  std::string name_;
  Handler handler_;
};

}  // namespace saccade::runtime
