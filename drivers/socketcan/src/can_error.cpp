#include "pliant/drivers/socketcan/can_error.hpp"

#include <cstring>

namespace pliant::drivers::socketcan {

bool decode_can_error(const CanFrame& frame, CanErrorReport& report) noexcept {
  if (!is_error_frame(frame)) return false;
  // Bytes past the dlc are treated as zero even if a transport left something there.
  std::uint8_t d[kCanMaxDlc] = {0, 0, 0, 0, 0, 0, 0, 0};
  const std::uint8_t n = frame.dlc > kCanMaxDlc ? kCanMaxDlc : frame.dlc;
  std::memcpy(d, frame.data, n);
  CanErrorReport r;
  r.classes = frame.id & kCanErrClassMask;
  if ((r.classes & kCanErrController) != 0) r.controller = d[1];
  if ((r.classes & kCanErrProtocol) != 0) {
    r.protocol_type = d[2];
    r.protocol_where = d[3];
  }
  if ((r.classes & kCanErrTransceiver) != 0) r.transceiver = d[4];
  if ((r.classes & kCanErrCounters) != 0) {
    r.tx_errors = d[6];
    r.rx_errors = d[7];
  }
  report = r;
  return true;
}

CanFrame make_can_error_frame(std::uint32_t classes, const std::uint8_t* data8) noexcept {
  CanFrame f;
  f.id = kCanErrFlag | (classes & kCanErrClassMask);
  f.dlc = kCanMaxDlc;
  if (data8 != nullptr) std::memcpy(f.data, data8, kCanMaxDlc);
  return f;
}

}  // namespace pliant::drivers::socketcan
