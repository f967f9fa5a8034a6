// `pliant devices [--all] [--json]`: what is connected that pliant can use: USB depth cameras and
// USB-CAN adapters (the discovery "usb" that drivers/usb registers: VID:PID table, sysfs strings,
// the adapter's canN interface), CAN network interfaces, video devices and serial ports; then the
// device schemes the drivers of this build registered (cli_registry.hpp). Works with nothing
// connected (and without the usb driver in the build: the USB part then says so).
#pragma once

#include <CLI/CLI.hpp>

namespace pliant::cli {

class DevicesCommand {
 public:
  /// Registers `devices` on `parent`.
  explicit DevicesCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  bool all_ = false;
  bool json_ = false;
};

}  // namespace pliant::cli
