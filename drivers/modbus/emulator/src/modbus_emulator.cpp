#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <thread>

#include "pliant/drivers/modbus/ft300_codec.hpp"
#include "pliant/drivers/modbus/modbus_crc.hpp"

namespace pliant::drivers::modbus {
namespace {

namespace r2f = robotiq2f;

// The holding-register block covers the FT 300 (180..185, 410) and the Robotiq command and
// status blocks (1000..1002, 2000..2002); the input-register block is the status alone.
constexpr int kHoldingStart = ft300::kWrenchRegister;
constexpr int kHoldingCount = r2f::kStatusRegister + r2f::kRegisterCount - kHoldingStart;
constexpr int kInputStart = r2f::kStatusRegister;
constexpr int kInputCount = r2f::kRegisterCount;
constexpr int kMaxAdu = 260;
constexpr int kMaxClients = 8;

std::uint16_t be16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>((static_cast<unsigned>(p[0]) << 8) | p[1]);
}

void put_be16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v & 0xffu);
}

void set_error(std::string* error, const std::string& what) {
  if (error != nullptr) *error = what + ": " + std::strerror(errno);
}

}  // namespace

struct ModbusEmulator::Impl {
  explicit Impl(const ModbusEmulatorConfig& c) : config(c), model(c.gripper) {}

  ModbusEmulatorConfig config;
  mutable std::mutex mutex;
  Robotiq2fModel model;
  double wrench[6] = {0, 0, 0, 0, 0, 0};
  modbus_t* ctx = nullptr;
  modbus_mapping_t* map = nullptr;
  int header_length = 0;
  int listen_fd = -1;
  int clients[kMaxClients] = {-1, -1, -1, -1, -1, -1, -1, -1};  // tcp; closed by the server thread only
  int master_fd = -1;                                           // rtu_pty
  int slave_hold_fd = -1;
  std::string path;
  std::uint16_t port = 0;
  int wake[2] = {-1, -1};
  std::thread thread;
  std::atomic<bool> stopping{false};
  bool started = false;
  unsigned drop = 0;
  unsigned corrupt = 0;
  bool fc04 = true;
  bool refuse = false;
  bool has_last_request = false;
  std::chrono::steady_clock::time_point last_request;
  ModbusEmulatorCounters counters;

  bool tcp() const noexcept { return config.transport == EmulatorTransport::tcp; }

  bool open_tcp(std::string* error);
  bool open_pty(std::string* error);
  void close_all();
  void run();
  void accept_client();
  void close_client(int slot);
  void receive_one(int fd, int slot);
  void handle(int fd, const std::uint8_t* q, int length);
  void sync_registers();
  void after_write(int address, int count);
  void apply_write_request(const std::uint8_t* q, int length);
  void send_corrupted(int fd, const std::uint8_t* q, int length);
};

bool ModbusEmulator::Impl::open_tcp(std::string* error) {
  ctx = modbus_new_tcp("127.0.0.1", config.port);
  if (ctx == nullptr) {
    set_error(error, "modbus_new_tcp");
    return false;
  }
  listen_fd = modbus_tcp_listen(ctx, 4);
  if (listen_fd < 0) {
    set_error(error, "modbus_tcp_listen");
    return false;
  }
  sockaddr_in address{};
  socklen_t size = sizeof address;
  if (getsockname(listen_fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) {
    set_error(error, "getsockname");
    return false;
  }
  port = ntohs(address.sin_port);
  return true;
}

bool ModbusEmulator::Impl::open_pty(std::string* error) {
  master_fd = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_fd < 0 || grantpt(master_fd) != 0 || unlockpt(master_fd) != 0) {
    set_error(error, "posix_openpt");
    return false;
  }
  char name[128];
  if (ptsname_r(master_fd, name, sizeof name) != 0) {
    set_error(error, "ptsname_r");
    return false;
  }
  path = name;
  // Holding the slave side open keeps the master from seeing a hang-up (EIO) whenever the
  // driver closes its end, so the driver can close and reopen the device freely.
  slave_hold_fd = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  termios tio{};
  if (slave_hold_fd < 0 || tcgetattr(slave_hold_fd, &tio) != 0) {
    set_error(error, "open pty slave");
    return false;
  }
  cfmakeraw(&tio);
  if (tcsetattr(slave_hold_fd, TCSANOW, &tio) != 0) {
    set_error(error, "tcsetattr");
    return false;
  }
  ctx = modbus_new_rtu(name, 115200, 'N', 8, 1);
  if (ctx == nullptr || modbus_set_slave(ctx, config.slave_id) != 0 || modbus_set_socket(ctx, master_fd) != 0) {
    set_error(error, "modbus_new_rtu");
    return false;
  }
  return true;
}

void ModbusEmulator::Impl::close_all() {
  if (ctx != nullptr) {
    modbus_set_socket(ctx, -1);
    modbus_free(ctx);
    ctx = nullptr;
  }
  for (int& fd : clients) {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  for (int* fd : {&listen_fd, &master_fd, &slave_hold_fd, &wake[0], &wake[1]}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
  if (map != nullptr) {
    modbus_mapping_free(map);
    map = nullptr;
  }
}

void ModbusEmulator::Impl::run() {
  while (!stopping.load()) {
    fd_set set;
    FD_ZERO(&set);
    FD_SET(wake[0], &set);
    int top = wake[0];
    int served[kMaxClients];
    int slots = 0;
    if (tcp()) {
      FD_SET(listen_fd, &set);
      if (listen_fd > top) top = listen_fd;
      for (int fd : clients) served[slots++] = fd;
    } else {
      served[slots++] = master_fd;
    }
    for (int i = 0; i < slots; ++i) {
      if (served[i] < 0) continue;
      FD_SET(served[i], &set);
      if (served[i] > top) top = served[i];
    }
    const int rc = select(top + 1, &set, nullptr, nullptr, nullptr);
    if (rc < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (stopping.load()) return;
    if (FD_ISSET(wake[0], &set)) {
      char sink[16];
      while (::read(wake[0], sink, sizeof sink) > 0) {
      }
    }
    if (tcp() && FD_ISSET(listen_fd, &set)) accept_client();
    for (int i = 0; i < slots; ++i) {
      if (served[i] >= 0 && FD_ISSET(served[i], &set)) receive_one(served[i], i);
    }
  }
}

void ModbusEmulator::Impl::accept_client() {
  const int s = modbus_tcp_accept(ctx, &listen_fd);  // also sets the context's socket to s
  std::lock_guard<std::mutex> lock(mutex);
  if (s < 0) return;
  int slot = -1;
  for (int i = 0; i < kMaxClients && slot < 0; ++i) {
    if (clients[i] < 0) slot = i;
  }
  if (refuse || slot < 0) {
    ++counters.refused;  // before the close: the client may look as soon as it sees the drop
    ::close(s);
    return;
  }
  clients[slot] = s;
  ++counters.connections;
}

// Called with the mutex held.
void ModbusEmulator::Impl::close_client(int slot) {
  ++counters.disconnects;
  ::close(clients[slot]);
  clients[slot] = -1;
}

void ModbusEmulator::Impl::receive_one(int fd, int slot) {
  std::uint8_t query[kMaxAdu];
  modbus_set_socket(ctx, fd);
  errno = 0;
  const int rc = modbus_receive(ctx, query);
  if (rc > 0) {
    handle(fd, query, rc);
    return;
  }
  const int err = errno;
  std::lock_guard<std::mutex> lock(mutex);
  if (rc == 0) {  // RTU: a request for another slave (or the answer to it), ignored
    ++counters.other_slave;
    return;
  }
  if (err == ETIMEDOUT) return;
  if (tcp()) {
    if (err != ECONNRESET) ++counters.bad_requests;
    close_client(slot);
    return;
  }
  ++counters.bad_requests;
  modbus_flush(ctx);
}

void ModbusEmulator::Impl::sync_registers() {
  std::uint16_t status[r2f::kRegisterCount];
  model.status_registers(status);
  for (int i = 0; i < r2f::kRegisterCount; ++i) {
    map->tab_input_registers[i] = status[i];
    map->tab_registers[r2f::kStatusRegister - kHoldingStart + i] = status[i];
  }
  double w[6];
  for (int i = 0; i < 6; ++i) w[i] = wrench[i];
  if (config.ft_grip_force_axis >= 0 && config.ft_grip_force_axis < 6)
    w[config.ft_grip_force_axis] += model.grip_force_n();
  ft300::wrench_to_registers(w, map->tab_registers + (ft300::kWrenchRegister - kHoldingStart));
}

void ModbusEmulator::Impl::after_write(int address, int count) {
  const int end = address + count;
  if (address < r2f::kCommandRegister + r2f::kRegisterCount && end > r2f::kCommandRegister) {
    model.write_command(r2f::decode_command(map->tab_registers + (r2f::kCommandRegister - kHoldingStart)));
    ++counters.command_writes;
  }
  if (address <= ft300::kStreamControlRegister && end > ft300::kStreamControlRegister &&
      map->tab_registers[ft300::kStreamControlRegister - kHoldingStart] == ft300::kStreamStart) {
    ++counters.stream_requests;
  }
}

// The write a damaged answer belongs to still reaches the device: apply it to the map by hand.
void ModbusEmulator::Impl::apply_write_request(const std::uint8_t* q, int length) {
  const int h = header_length;
  const int fn = q[h];
  int address = 0, count = 0;
  std::uint16_t values[125];
  if (fn == 0x06 && length >= h + 5) {
    address = be16(q + h + 1);
    count = 1;
    values[0] = be16(q + h + 3);
  } else if (fn == 0x10 && length >= h + 6) {
    address = be16(q + h + 1);
    count = be16(q + h + 3);
    if (count < 1 || count > 123 || length < h + 6 + 2 * count) return;
    for (int i = 0; i < count; ++i) values[i] = be16(q + h + 6 + 2 * i);
  } else {
    return;
  }
  if (address < kHoldingStart || address + count > kHoldingStart + kHoldingCount) return;
  for (int i = 0; i < count; ++i) map->tab_registers[address - kHoldingStart + i] = values[i];
  after_write(address, count);
}

void ModbusEmulator::Impl::send_corrupted(int fd, const std::uint8_t* q, int length) {
  const int h = header_length;
  const int fn = q[h];
  std::uint8_t pdu[kMaxAdu];
  int pdu_size = 0;
  pdu[pdu_size++] = static_cast<std::uint8_t>(fn);
  if ((fn == 0x03 || fn == 0x04) && length >= h + 5) {
    const int address = be16(q + h + 1);
    int count = be16(q + h + 3);
    if (count > 125) count = 125;
    pdu[pdu_size++] = static_cast<std::uint8_t>(2 * count);
    for (int i = 0; i < count; ++i) {
      const int a = address + i;
      std::uint16_t v = 0;
      if (fn == 0x04 && a >= kInputStart && a < kInputStart + kInputCount)
        v = map->tab_input_registers[a - kInputStart];
      if (fn == 0x03 && a >= kHoldingStart && a < kHoldingStart + kHoldingCount)
        v = map->tab_registers[a - kHoldingStart];
      put_be16(pdu + pdu_size, v);
      pdu_size += 2;
    }
  } else if ((fn == 0x06 || fn == 0x10) && length >= h + 5) {
    std::memcpy(pdu + pdu_size, q + h + 1, 4);  // address and count (or value): an echo
    pdu_size += 4;
  }
  std::uint8_t adu[kMaxAdu + 8];
  int size = 0;
  if (tcp()) {
    // MBAP header with the transaction ID off by one: a reply to some other request.
    put_be16(adu, static_cast<std::uint16_t>(be16(q) + 1u));
    put_be16(adu + 2, 0);
    put_be16(adu + 4, static_cast<std::uint16_t>(pdu_size + 1));
    adu[6] = q[h - 1];
    std::memcpy(adu + 7, pdu, static_cast<std::size_t>(pdu_size));
    size = 7 + pdu_size;
    (void)::send(fd, adu, static_cast<std::size_t>(size), MSG_NOSIGNAL);
    return;
  }
  adu[0] = q[0];
  std::memcpy(adu + 1, pdu, static_cast<std::size_t>(pdu_size));
  size = 1 + pdu_size;
  append_modbus_crc16(adu, static_cast<std::size_t>(size));
  adu[size] = static_cast<std::uint8_t>(adu[size] ^ 0xffu);  // a CRC that does not match
  size += 2;
  (void)::write(fd, adu, static_cast<std::size_t>(size));
}

void ModbusEmulator::Impl::handle(int fd, const std::uint8_t* q, int length) {
  std::lock_guard<std::mutex> lock(mutex);
  const int h = header_length;
  if (length <= h || q[h - 1] != config.slave_id) {
    ++counters.other_slave;
    return;
  }
  ++counters.requests;
  if (config.real_time) {
    const auto now = std::chrono::steady_clock::now();
    if (has_last_request) model.step(std::chrono::duration<double>(now - last_request).count());
    last_request = now;
    has_last_request = true;
  }
  sync_registers();
  const int fn = q[h];
  if (drop > 0) {
    --drop;
    ++counters.dropped;
    return;
  }
  if (fn == 0x04 && !fc04) {
    modbus_reply_exception(ctx, q, MODBUS_EXCEPTION_ILLEGAL_FUNCTION);
    ++counters.replies;
    ++counters.exceptions;
    return;
  }
  if (corrupt > 0) {
    --corrupt;
    ++counters.corrupted;
    apply_write_request(q, length);
    send_corrupted(fd, q, length);
    return;
  }
  modbus_reply(ctx, q, length, map);
  ++counters.replies;
  if ((fn == 0x06 || fn == 0x10) && length >= h + 5) {
    after_write(be16(q + h + 1), fn == 0x06 ? 1 : be16(q + h + 3));
  }
}

ModbusEmulator::ModbusEmulator(const ModbusEmulatorConfig& config) : impl_(std::make_unique<Impl>(config)) {}

ModbusEmulator::~ModbusEmulator() { stop(); }

bool ModbusEmulator::start(std::string* error) {
  Impl& m = *impl_;
  if (m.started) {
    if (error != nullptr) *error = "already started";
    return false;
  }
  if (m.config.slave_id < 1 || m.config.slave_id > 247 ||
      r2f::validate(m.config.gripper.scaling) != hal::HalStatus::ok) {
    if (error != nullptr) *error = "invalid configuration";
    return false;
  }
  if (pipe2(m.wake, O_CLOEXEC | O_NONBLOCK) != 0) {
    set_error(error, "pipe2");
    return false;
  }
  m.map = modbus_mapping_new_start_address(0, 0, 0, 0, kHoldingStart, kHoldingCount, kInputStart, kInputCount);
  if (m.map == nullptr) {
    set_error(error, "modbus_mapping_new_start_address");
    m.close_all();
    return false;
  }
  const bool opened = m.tcp() ? m.open_tcp(error) : m.open_pty(error);
  if (!opened) {
    m.close_all();
    return false;
  }
  m.header_length = modbus_get_header_length(m.ctx);
  {
    std::lock_guard<std::mutex> lock(m.mutex);
    m.sync_registers();
  }
  m.stopping.store(false);
  m.thread = std::thread([&m] { m.run(); });
  m.started = true;
  return true;
}

void ModbusEmulator::stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.stopping.store(true);
  const char byte = 1;
  (void)::write(m.wake[1], &byte, 1);
  m.thread.join();
  m.close_all();
  m.started = false;
}

std::uint16_t ModbusEmulator::port() const { return impl_->port; }
std::string ModbusEmulator::device_path() const { return impl_->path; }

void ModbusEmulator::advance(double dt_s) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->model.step(dt_s);
}

void ModbusEmulator::set_object(double width_m, double stiffness_n_per_m) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->model.set_object(width_m, stiffness_n_per_m);
}

void ModbusEmulator::set_object_model(const Robotiq2fObject* object) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->model.set_object_model(object);
}

void ModbusEmulator::set_gripper_width(double width_m) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->model.set_width(width_m);
}

void ModbusEmulator::set_gripper_fault(std::uint8_t fault_byte) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->model.set_fault(fault_byte);
}

void ModbusEmulator::set_wrench(const double wrench[6]) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  for (int i = 0; i < 6; ++i) impl_->wrench[i] = wrench[i];
}

EmulatedGripperState ModbusEmulator::gripper() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  EmulatedGripperState s;
  s.width_m = impl_->model.width_m();
  s.grip_force_n = impl_->model.grip_force_n();
  s.moving = impl_->model.moving();
  s.status = impl_->model.status();
  s.command = impl_->model.command();
  return s;
}

std::uint16_t ModbusEmulator::holding_register(int address) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->map == nullptr || address < kHoldingStart || address >= kHoldingStart + kHoldingCount) return 0;
  return impl_->map->tab_registers[address - kHoldingStart];
}

void ModbusEmulator::drop_replies(unsigned count) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->drop = count;
}

void ModbusEmulator::corrupt_replies(unsigned count) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->corrupt = count;
}

void ModbusEmulator::set_fc04_supported(bool supported) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->fc04 = supported;
}

bool ModbusEmulator::disconnect_clients() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (!impl_->tcp()) return false;
  // The server thread sees the end of each stream and closes the socket (it owns the fds).
  bool any = false;
  for (int fd : impl_->clients) {
    if (fd >= 0 && ::shutdown(fd, SHUT_RDWR) == 0) any = true;
  }
  return any;
}

void ModbusEmulator::set_refuse_connections(bool refuse) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->refuse = refuse;
}

ModbusEmulatorCounters ModbusEmulator::counters() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->counters;
}

}  // namespace pliant::drivers::modbus
