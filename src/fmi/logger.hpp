// SPDX-License-Identifier: BSD-2-Clause
// Messages to the importer's logger callback, filtered by log category.
//
// Categories (declared in every modelDescription.xml, in this order):
//   logEvents         mode changes, stop contacts, guard crossings (status OK)
//   logStatusWarning  the reason of every Warning
//   logStatusDiscard  the reason of every Discard
//   logStatusError    the reason of every Error
//   logStatusFatal    the reason of every Fatal
//   logCalls          every FMI call with its arguments (verbose; only when named)
//
// One rule for instantiation and fmiXSetDebugLogging (FMI 2.0.4 section
// 2.1.5, FMI 3.0 fmi3SetDebugLogging):
//   - logging off (loggingOn = false, or SetDebugLogging(false) with no
//     category named): the four logStatus* categories only, so that a status
//     other than OK always comes with its reason;
//   - logging on with no category named (loggingOn = true, or
//     SetDebugLogging(true) with no category named): those and logEvents;
//   - SetDebugLogging(true, categories): exactly the named categories, the
//     others off ("only debug messages according to the categories");
//   - SetDebugLogging(false, categories): the named categories off, the
//     others keep their setting.
// logCalls is on only when named. FMI 2.0: whatever the setting, the reason
// of an Error or a Fatal reaches the importer: switching debug logging off
// does not hide why an instance became unusable. FMI 3.0 (categories_only):
// logMessage "must only be called for log categories that were enabled"
// (3.0.2 2.3.1), so logging off means no message at all; the reason of the
// last Error or Fatal is kept as the last-error text whatever the setting.
#pragma once

#include <cstdarg>
#include <string>

#include "fmi/fmi_status.hpp"

namespace pkm_fmi {

enum class LogCategory : unsigned { Events, StatusWarning, StatusDiscard, StatusError, StatusFatal, Calls };
constexpr int kLogCategoryCount = 6;
inline constexpr const char* kLogCategoryNames[kLogCategoryCount] = {
    "logEvents", "logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal", "logCalls"};
inline constexpr const char* kLogCategoryDescriptions[kLogCategoryCount] = {
    "Mode changes, end-stop contacts and singularity-guard crossings",
    "Reasons of the status Warning",
    "Reasons of the status Discard (a step or state that could not be used)",
    "Reasons of the status Error",
    "Reasons of the status Fatal",
    "Every call of an FMI function with its arguments (verbose; enabled only by naming it)"};

/// The category of a name, -1 if unknown.
int log_category(const char* name);

#if defined(__MINGW32__)
#define PKM_FMI_PRINTF(fmt, args) __attribute__((format(__MINGW_PRINTF_FORMAT, fmt, args)))
#elif defined(__GNUC__)
#define PKM_FMI_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define PKM_FMI_PRINTF(fmt, args)
#endif

/// Hands one formatted message to the importer (the FMI version's callback).
using LogEmitter = void (*)(void* callback, void* env, const char* instance, Status status, const char* category,
                            const char* message);

class Logger {
 public:
  Logger() = default;
  Logger(LogEmitter emit, void* callback, void* env, std::string instance_name, bool logging_on,
         bool categories_only = false);

  bool enabled(LogCategory c) const {
    return callback_ && (on_[static_cast<unsigned>(c)] ||
                         (!categories_only_ && (c == LogCategory::StatusError || c == LogCategory::StatusFatal)));
  }
  /// The last Error or Fatal message, logged or not ("" if none).
  const char* last_error() const { return last_error_; }
  /// The default set of categories for logging on or off (see above).
  void set_default(bool logging_on);
  /// Categories named in SetDebugLogging (see above): on = true selects
  /// exactly `named`, on = false switches `named` off.
  void select(const bool (&named)[kLogCategoryCount], bool on);

  void error(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void warning(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void discard(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void event(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void call(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);  // logCalls

  const std::string& instance_name() const { return name_; }

 private:
  void vlog(Status status, LogCategory c, const char* fmt, va_list args);

  LogEmitter emit_ = nullptr;
  void* callback_ = nullptr;
  void* env_ = nullptr;
  std::string name_;
  bool on_[kLogCategoryCount] = {};
  bool categories_only_ = false;
  char last_error_[1024] = {};
};

}  // namespace pkm_fmi
