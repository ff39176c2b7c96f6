// SPDX-License-Identifier: MIT
// Test support: ODE's own error, debug and warning messages become test failures.
//
// ODE reports trouble through three handlers (ode/error.h, ode/src/error.cpp of ODE 0.16):
//   - dError (fatal errors) calls the error handler and then exit(1);
//   - dDebug (internal and argument assertions: dIASSERT, dUASSERT, dAASSERT) calls the debug
//     handler and then abort() (dICHECK even writes through a null pointer after it);
//   - dMessage (warnings: "mass must be > 0", "inertia must be positive definite", "zero length
//     vector", "LCP internal error, s <= 0", "destroying world containing grouped joints") calls
//     the message handler and returns: ODE goes on.
// error.h says that the error and debug handlers "should not return". A handler may not return
// by throwing or longjmp-ing, but either would unwind or skip ODE's own frames in the middle of
// an operation (a space locked inside dSpaceCollide, a half-built step) and leave the library in
// a state nothing can test further; longjmp over C++ frames is undefined behaviour besides. So
// this guard never leaves the handler abnormally: for an error or debug message it records the
// message, adds a googletest failure that names the test and the message (printed at once by
// googletest's printer), flushes the output and returns - ODE then ends the process (exit code
// 1 or SIGABRT), and ctest reports the test binary as failed with the message just above. A
// warning (dMessage) is recorded and added as a failure; the test goes on.
//
// OdeMessageGuard installs the handlers for its lifetime and restores the previous ones (guards
// nest: the innermost one receives the messages). OdeMessageListener creates one around every
// test of a binary; ode_world.hpp registers it, so every test of a binary that includes
// ode_world.hpp (all the plugin tests) runs under it. A test that provokes an ODE warning on
// purpose opens an inner guard with Policy::Record and checks messages().
#pragma once

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <cstdarg>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace rheofeed::test {

class OdeMessageGuard {
 public:
  /// What a message does besides being recorded.
  enum class Policy {
    Fail,    ///< every message is a test failure (errors and debug messages then end the process)
    Record,  ///< only recorded (errors and debug messages still end the process: ODE does it)
  };
  /// Which of ODE's handlers received the message.
  enum class Kind { Error, Debug, Message };
  struct Message {
    Kind kind;
    int number;        ///< ODE's errnum (d_ERR_IASSERT = 1, d_ERR_UASSERT = 2, d_ERR_LCP = 3)
    std::string text;  ///< the formatted message
  };

  explicit OdeMessageGuard(Policy policy = Policy::Fail)
      : policy_(policy),
        outer_(innermost()),
        previous_error_(dGetErrorHandler()),
        previous_debug_(dGetDebugHandler()),
        previous_message_(dGetMessageHandler()) {
    innermost() = this;
    dSetErrorHandler(&OdeMessageGuard::onError);
    dSetDebugHandler(&OdeMessageGuard::onDebug);
    dSetMessageHandler(&OdeMessageGuard::onMessage);
  }
  ~OdeMessageGuard() {
    dSetErrorHandler(previous_error_);
    dSetDebugHandler(previous_debug_);
    dSetMessageHandler(previous_message_);
    innermost() = outer_;
  }
  OdeMessageGuard(const OdeMessageGuard&) = delete;
  OdeMessageGuard& operator=(const OdeMessageGuard&) = delete;

  /// Messages received while this guard was the innermost one, in order.
  const std::vector<Message>& messages() const { return messages_; }

  static const char* name(Kind kind) {
    switch (kind) {
      case Kind::Error:
        return "ODE error";
      case Kind::Debug:
        return "ODE internal error (debug)";
      case Kind::Message:
        return "ODE message";
    }
    return "ODE";
  }

 private:
  static OdeMessageGuard*& innermost() {
    static OdeMessageGuard* guard = nullptr;
    return guard;
  }

  static void onError(int number, const char* format, va_list args) {
    receive(Kind::Error, number, format, args);
  }
  static void onDebug(int number, const char* format, va_list args) {
    receive(Kind::Debug, number, format, args);
  }
  static void onMessage(int number, const char* format, va_list args) {
    receive(Kind::Message, number, format, args);
  }

  // Called by ODE (a C caller): nothing may leave it by an exception.
  static void receive(Kind kind, int number, const char* format, va_list args) noexcept {
    char text[2048];
    std::vsnprintf(text, sizeof text, format ? format : "(null)", args);
    const bool fatal = kind != Kind::Message;
    const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
    const std::string test_name =
        test ? std::string(test->test_suite_name()) + "." + test->name() : "(no test running)";
    if (fatal) {
      // Said first, in case googletest's output does not reach the terminal before ODE ends
      // the process.
      std::fflush(stdout);
      std::fprintf(stderr, "\n%s %d in %s: %s\n(ODE ends the process after this message: %s)\n",
                   name(kind), number, test_name.c_str(), text,
                   kind == Kind::Error ? "exit(1)" : "abort()");
      std::fflush(stderr);
    }
    OdeMessageGuard* guard = innermost();
    try {
      if (guard) guard->messages_.push_back({kind, number, text});
      if (!guard || guard->policy_ == Policy::Fail) {
        ADD_FAILURE() << name(kind) << " " << number << ": " << text;
      }
    } catch (...) {
      std::fprintf(stderr, "OdeMessageGuard: could not record \"%s\"\n", text);
    }
    std::fflush(stdout);
    std::fflush(stderr);
  }

  Policy policy_;
  OdeMessageGuard* outer_;
  dMessageFunction* previous_error_;
  dMessageFunction* previous_debug_;
  dMessageFunction* previous_message_;
  std::vector<Message> messages_;
};

/// Puts every test under an OdeMessageGuard (Policy::Fail), from its start to its end (the
/// fixture's SetUp and TearDown included).
class OdeMessageListener : public testing::EmptyTestEventListener {
 public:
  void OnTestStart(const testing::TestInfo&) override {
    guard_ = std::make_unique<OdeMessageGuard>();
  }
  void OnTestEnd(const testing::TestInfo&) override { guard_.reset(); }

 private:
  std::unique_ptr<OdeMessageGuard> guard_;
};

/// Registers one OdeMessageListener per test binary (googletest owns it). Evaluated during
/// static initialisation, before gtest_main runs the tests.
inline const bool kOdeMessagesFailTests = [] {
  testing::UnitTest::GetInstance()->listeners().Append(new OdeMessageListener);
  return true;
}();

}  // namespace rheofeed::test
