#include "exit_status.hpp"

#include <exception>
#include <iostream>
#include <new>

#include "pliant/host/recording.hpp"

namespace pliant::cli {

std::string single_line(std::string message) {
  for (char& c : message) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!message.empty() && message.back() == ' ') message.pop_back();
  return message;
}

void report_error(const std::string& prefix, const std::string& message) {
  std::cout.flush();
  std::cerr << prefix << ": " << single_line(message) << std::endl;
}

void report_warning(const std::string& message) { report_error("pliant: warning", message); }

int run_reporting_errors(const std::string& prefix, const std::function<int()>& command) {
  try {
    return command();
  } catch (const host::RecordingError& e) {
    report_error(prefix, e.what());
    return exit_usage;
  } catch (const UsageError& e) {
    report_error(prefix, e.what());
    return exit_usage;
  } catch (const std::bad_alloc&) {
    report_error(prefix, "out of memory");
    return exit_failure;
  } catch (const std::exception& e) {
    report_error(prefix, e.what());
    return exit_failure;
  } catch (...) {
    report_error(prefix, "unexpected internal error");
    return exit_failure;
  }
}

}  // namespace pliant::cli
