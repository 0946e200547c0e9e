// SPDX-License-Identifier: BSD-2-Clause
#include "fmi/logger.hpp"

#include <cstdio>
#include <cstring>
#include <utility>

namespace pkm_fmi {

int log_category(const char* name) {
  if (!name) return -1;
  for (int c = 0; c < kLogCategoryCount; ++c)
    if (std::strcmp(name, kLogCategoryNames[c]) == 0) return c;
  return -1;
}

Logger::Logger(LogEmitter emit, void* callback, void* env, std::string instance_name, bool logging_on,
               bool categories_only)
    : emit_(emit), callback_(emit ? callback : nullptr), env_(env), name_(std::move(instance_name)),
      categories_only_(categories_only) {
  set_default(logging_on);
}

void Logger::set_default(bool logging_on) {
  for (bool& b : on_) b = false;
  if (categories_only_ && !logging_on) return;  // FMI 3.0: logging off, nothing at all
  for (LogCategory c : {LogCategory::StatusWarning, LogCategory::StatusDiscard, LogCategory::StatusError,
                        LogCategory::StatusFatal})
    on_[static_cast<unsigned>(c)] = true;
  on_[static_cast<unsigned>(LogCategory::Events)] = logging_on;
}

void Logger::select(const bool (&named)[kLogCategoryCount], bool on) {
  for (int c = 0; c < kLogCategoryCount; ++c)
    if (on || named[c]) on_[c] = on && named[c];
}

void Logger::vlog(Status status, LogCategory c, const char* fmt, va_list args) {
  if (c == LogCategory::StatusError || c == LogCategory::StatusFatal) {
    va_list copy;
    va_copy(copy, args);
    if (std::vsnprintf(last_error_, sizeof last_error_, fmt, copy) < 0) last_error_[0] = '\0';
    va_end(copy);
  }
  if (!enabled(c)) return;
  // On the stack when it fits (every message of this FMU does): logging an
  // event inside a step allocates nothing.
  char small[1024];
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(small, sizeof small, fmt, copy);
  va_end(copy);
  const char* name = name_.c_str();
  const char* category = kLogCategoryNames[static_cast<unsigned>(c)];
  if (n < 0) {
    emit_(callback_, env_, name, status, category, fmt);
  } else if (static_cast<std::size_t>(n) < sizeof small) {
    emit_(callback_, env_, name, status, category, small);
  } else {
    std::string text(static_cast<std::size_t>(n) + 1, '\0');
    std::vsnprintf(&text[0], text.size(), fmt, args);
    text.resize(static_cast<std::size_t>(n));
    emit_(callback_, env_, name, status, category, text.c_str());
  }
}

#define PKM_FMI_LOG_AS(method, status, category) \
  void Logger::method(const char* fmt, ...) {    \
    va_list args;                                \
    va_start(args, fmt);                         \
    vlog(status, category, fmt, args);           \
    va_end(args);                                \
  }
PKM_FMI_LOG_AS(error, Status::Error, LogCategory::StatusError)
PKM_FMI_LOG_AS(warning, Status::Warning, LogCategory::StatusWarning)
PKM_FMI_LOG_AS(discard, Status::Discard, LogCategory::StatusDiscard)
PKM_FMI_LOG_AS(event, Status::OK, LogCategory::Events)
PKM_FMI_LOG_AS(call, Status::OK, LogCategory::Calls)
#undef PKM_FMI_LOG_AS

}  // namespace pkm_fmi
