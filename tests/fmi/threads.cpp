// SPDX-License-Identifier: BSD-2-Clause
// Hardening, threads: eight instances of the plant FMU (and eight of the
// inverse FMU) advanced concurrently in eight std::threads through the
// built, dlopen'd binaries give results bit-identical to each instance run
// alone; and the binaries hold no global or static mutable state of their
// own (only the C++ runtime's and Eigen's thread-safe cache-size constants).
// One instance called from two threads at once (not allowed by FMI) answers
// the second call with fmi2Error instead of racing the first.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "fmu_fixture.hpp"

namespace {

using namespace pkm_test;

constexpr int kThreads = 8;
constexpr int kSteps = 600;  // 0.6 s at 1 ms

/// One worker's run: a plant and an inverse instance, each configured by
/// the worker's index (solver, formulation, initial state, input amplitudes),
/// with input derivatives and an FMU state save/restore in the middle. Every
/// output after every step goes into the trace.
std::vector<double> work(int k, const std::atomic<bool>* go) {
  std::vector<double> trace;
  trace.reserve(static_cast<std::size_t>(kSteps) * 80);
  const std::string name = "w" + std::to_string(k);
  PlantFmu p(name.c_str());
  InverseFmu inv(name.c_str());
  if (!p.c || !inv.c) return {};
  p.set_int("solver", k % 2);            // CVODE and RK4
  p.set_int("formulation", 2 - (k / 2) % 3);  // the three forward formulations
  p.set("x0", 1e-3 * (k - 3.5));
  p.set("dphi0", 0.01 * k);
  p.set("m_platform", 0.45474 * (1.0 + 0.01 * k));
  // Some of these runs end on the plant's lower end stops; the inverse FMU,
  // asked at those poses, would warn of a pose beyond them (once): not this
  // test's subject, so its stops are moved out of the way.
  inv.set("rho_min", -1.0);
  if (go) {
    while (!go->load(std::memory_order_acquire)) std::this_thread::yield();
  }
  p.initialize();
  inv.initialize();
  const double amp = 0.005 * (1 + k), w = 2.0 * kPi * (1.0 + 0.25 * k);
  fmi2FMUstate mid = nullptr;
  double t = 0.0;
  for (int s = 0; s < kSteps; ++s) {
    for (int i = 1; i <= 4; ++i) {
      const double phase = 0.7 * i;
      p.set(force_name(i), kStaticForce + amp * std::sin(w * t + phase));
      p.set_derivative(force_name(i), amp * w * std::cos(w * t + phase));
    }
    p.set("Me_z", 1e-4 * k * std::cos(3.0 * t));
    if (s == kSteps / 2) p.lib.fmi2GetFMUstate(p.c, &mid);
    if (p.step(t, 1e-3) != fmi2OK) {
      trace.push_back(-1.0);  // makes the comparison fail
      break;
    }
    t += 1e-3;
    const std::vector<double> out = p.outputs();
    trace.insert(trace.end(), out.begin(), out.end());
    // The inverse FMU at the pose the plant reached.
    inv.set("x", out[0]);
    inv.set("y", out[1]);
    inv.set("z", out[2]);
    inv.set("phi", out[3]);
    inv.set("ddz", 0.1 * std::sin(w * t));
    const std::vector<double> F = inv.outputs();
    trace.insert(trace.end(), F.begin(), F.end());
  }
  // Back to the middle, and the second half once more.
  if (mid && p.lib.fmi2SetFMUstate(p.c, mid) == fmi2OK) {
    t = (kSteps / 2) * 1e-3;
    for (int s = kSteps / 2; s < kSteps; s += 10) {
      if (p.step(t, 1e-3) != fmi2OK) break;
      t += 1e-3;
      const std::vector<double> out = p.outputs();
      trace.insert(trace.end(), out.begin(), out.end());
    }
  }
  p.lib.fmi2FreeFMUstate(p.c, &mid);
  trace.push_back(static_cast<double>(p.log.messages.size() + inv.log.messages.size()));
  return trace;
}

TEST(HardeningThreads, EightConcurrentInstancesAreBitIdenticalToSoloRuns) {
  ASSERT_TRUE(plant_library().missing.empty()) << plant_library().missing;
  ASSERT_TRUE(inverse_library().missing.empty()) << inverse_library().missing;
  std::vector<std::vector<double>> solo(kThreads);
  for (int k = 0; k < kThreads; ++k) {
    solo[k] = work(k, nullptr);
    ASSERT_GT(solo[k].size(), static_cast<std::size_t>(kSteps)) << "worker " << k;
    ASSERT_EQ(solo[k].back(), 0.0) << "worker " << k << " logged messages";
  }
  for (int round = 0; round < 3; ++round) {
    std::vector<std::vector<double>> concurrent(kThreads);
    std::atomic<bool> go{false};
    std::vector<std::thread> threads;
    for (int k = 0; k < kThreads; ++k)
      threads.emplace_back([k, &concurrent, &go] { concurrent[k] = work(k, &go); });
    go.store(true, std::memory_order_release);
    for (auto& th : threads) th.join();
    for (int k = 0; k < kThreads; ++k)
      EXPECT_TRUE(bit_identical(concurrent[k], solo[k])) << "round " << round << ", worker " << k;
  }
  table_row("8 plant and 8 inverse instances in 8 std::threads at once (CVODE and RK4, the three formulations, "
            "input derivatives, FMU state get/set), 3 rounds",
            "every output of every step bit-identical to the same instance run alone",
            "yes: no interference between instances");
}

TEST(HardeningThreads, TheBinariesHaveNoMutableStaticDataOfTheirOwn) {
  // Writable data (.data, .bss, thread-local) of the FMU binaries: only the
  // statically linked C++ runtime's (exception handling, unwinder, new
  // handler) and Eigen's cache sizes (a function-local static, initialised
  // thread-safely once, for dynamic-size products; constant afterwards).
  const std::set<std::string> runtime = {
      "completed.0", "__dso_handle", "__TMC_END__", "DW.ref.__gxx_personality_v0", "DW.ref.__gcc_personality_v0",
      "DW.ref._ZTISt9exception", "DW.ref._ZTIN10__cxxabiv115__forced_unwindE", "__cxxabiv1::__unexpected_handler",
      "__cxxabiv1::__terminate_handler", "(anonymous namespace)::emergency_pool", "(anonymous namespace)::__new_handler",
      "__gnu_cxx::__verbose_terminate_handler()::terminating", "dwarf_reg_size_table", "once_regsizes.0", "marker.2",
      "object_mutex", "unseen_objects", "seen_objects", "any_objects_registered",
      "std::string::_Rep::_S_empty_rep_storage",
      "Eigen::internal::manage_caching_sizes(Eigen::Action, long*, long*, long*)::m_cacheSizes",
      "guard variable for Eigen::internal::manage_caching_sizes(Eigen::Action, long*, long*, long*)::m_cacheSizes"};
  for (const char* so : {PKM_FMU_PLANT_SO, PKM_FMU_INVERSE_SO}) {
    std::vector<std::string> lines;
    std::string out;
    if (!tool_lines("objdump -t -C", so, lines, &out)) GTEST_SKIP() << "objdump not available: " << out;
    int writable = 0;
    for (const std::string& line : lines) {
      const bool data = line.find(" .data\t") != std::string::npos || line.find(" .bss\t") != std::string::npos ||
                        line.find(" .tdata\t") != std::string::npos || line.find(" .tbss\t") != std::string::npos;
      if (!data || line.find(" O ") == std::string::npos) continue;
      // objdump -t: "<addr> <flags> O <section>\t<size> <name>"
      std::string name = line.substr(line.find('\t') + 1);
      name = name.substr(name.find_first_not_of("0123456789abcdef"));
      name = name.substr(name.find_first_not_of(' '));
      ++writable;
      EXPECT_TRUE(runtime.count(name)) << so << ": writable static data " << name;
    }
    EXPECT_GT(writable, 0) << out.substr(0, 2000);
  }
  table_row("objdump -t of both FMU binaries: every object in .data, .bss, .tdata, .tbss",
            "only the static C++ runtime's and Eigen's cache-size constants; nothing of the model, the FMI layer or "
            "SUNDIALS",
            "instances share nothing mutable");
}

/// The 50 ms step from t = 0 of `p` in a thread of its own, held inside
/// fmi2DoStep from the constructor's return until finish(): the step's
/// first log message (category logCalls, "fmi2DoStep(t, h)", logged inside
/// the call) arrives in the stepping thread, which waits there. So the
/// other thread's calls meet a step under way, however loaded the machine.
class StepInAnotherThread {
 public:
  explicit StepInAnotherThread(PlantFmu& p) : p_(p) {
    EXPECT_EQ(p.lib.fmi2SetDebugLogging(p.c, fmi2True, 1, kCalls), fmi2OK) << p.log.dump();
    p.log.on_message = [this](const LogMessage& m) {
      if (m.text.rfind("fmi2DoStep(", 0) != 0) return;  // not the step's: another thread's, go on
      std::unique_lock<std::mutex> lock(mutex_);
      inside_ = true;
      changed_.notify_all();
      changed_.wait(lock, [this] { return released_; });
    };
    thread_ = std::thread([this] { status_ = p_.step(0.0, 0.05); });
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, std::chrono::seconds(60), [this] { return inside_; });
  }
  /// The step logged its call and waits inside fmi2DoStep (false if it did
  /// not within a minute).
  bool inside() {
    std::lock_guard<std::mutex> lock(mutex_);
    return inside_;
  }
  ~StepInAnotherThread() {
    if (thread_.joinable()) finish();
  }
  StepInAnotherThread(const StepInAnotherThread&) = delete;
  StepInAnotherThread& operator=(const StepInAnotherThread&) = delete;
  /// Lets the step go on and waits for it; its status. Call logging off again.
  fmi2Status finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      released_ = true;
    }
    changed_.notify_all();
    thread_.join();
    p_.log.on_message = nullptr;
    EXPECT_EQ(p_.lib.fmi2SetDebugLogging(p_.c, fmi2False, 1, kCalls), fmi2OK) << p_.log.dump();
    return status_;
  }

 private:
  static constexpr fmi2String kCalls[1] = {"logCalls"};
  PlantFmu& p_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool inside_ = false, released_ = false;
  fmi2Status status_ = fmi2Fatal;
  std::thread thread_;
};

TEST(HardeningThreads, ASecondThreadOnTheSameInstanceIsRefused) {
  // While another thread is inside a 50 ms fmi2DoStep (RK4 at 1 us, 5e4 RK4
  // steps once it goes on), this thread reads the instance: every read is
  // refused.
  PlantFmu p("shared"), twin("twin");
  for (PlantFmu* q : {&p, &twin}) slow_rk4(*q);
  const fmi2ValueReference x = p.vr("x");
  constexpr int kReads = 100;
  int refused = 0;
  {
    StepInAnotherThread stepper(p);
    ASSERT_TRUE(stepper.inside()) << p.log.dump();
    for (int k = 0; k < kReads; ++k) {
      double v = 0.0;
      refused += p.lib.fmi2GetReal(p.c, &x, 1, &v) == fmi2Error;
    }
    ASSERT_EQ(stepper.finish(), fmi2OK) << p.log.dump();
  }
  EXPECT_EQ(refused, kReads) << p.log.dump();
  EXPECT_TRUE(p.log.contains("fmi2GetReal: called while another call on this instance is running")) << p.log.dump();
  // The step itself was not disturbed.
  ASSERT_EQ(twin.step(0.0, 0.05), fmi2OK);
  EXPECT_TRUE(bit_identical(p.outputs(), twin.outputs()));
  table_row("one instance from two threads: fmi2GetReal in a loop while another thread is inside a 50 ms "
            "fmi2DoStep",
            "every read during the step: fmi2Error \"called while another call on this instance is running (from "
            "another thread?)\" (" + std::to_string(refused) + " of " + std::to_string(kReads) + " refused)",
            "yes: the step completes bit-identical to an undisturbed twin's");
}

TEST(HardeningThreads, FreeingAnInstanceWhileAnotherThreadStepsItIsRefused) {
  // As above: another thread frees the instance while the step is under
  // way. Deleting it would pull the memory from under the step.
  PlantFmu p("shared"), twin("twin");
  for (PlantFmu* q : {&p, &twin}) slow_rk4(*q);
  {
    StepInAnotherThread stepper(p);
    ASSERT_TRUE(stepper.inside()) << p.log.dump();
    p.lib.fmi2FreeInstance(p.c);
    ASSERT_EQ(stepper.finish(), fmi2OK) << p.log.dump();
  }
  EXPECT_TRUE(p.log.contains("fmi2FreeInstance: called while another call on this instance is running"))
      << p.log.dump();
  // Still alive and undisturbed: it answers, equal to the twin, and is freed
  // at the end of the test (PlantFmu's destructor; valgrind's run checks leaks).
  ASSERT_EQ(twin.step(0.0, 0.05), fmi2OK);
  EXPECT_TRUE(bit_identical(p.outputs(), twin.outputs()));
  table_row("fmi2FreeInstance from a second thread while it is inside a 50 ms fmi2DoStep",
            "refused with an error \"called while another call on this instance is running\"; the instance "
            "stays alive",
            "yes: the step completes bit-identical to an undisturbed twin's; a later FreeInstance frees it");
}

}  // namespace
