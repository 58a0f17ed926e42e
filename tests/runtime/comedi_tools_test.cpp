// Comedi's own programs on the emulated NI PCI-6229 (emulation/comedi): Debian's
// comedi_board_info and comedi_test (built against the real libcomedi0) loaded with the emulation
// through LD_LIBRARY_PATH, and comedilib's demos (built here from the sources libcomedi-dev
// ships, linked against the emulation). Each must do what it does on a PCI-6229 that ni_pcimio
// attached without an interrupt line, or fail the way that board fails it. And the emulation
// must export every (symbol, version) of the real library, so that any Comedi program loads.
#include <comedi_errno.h>
#include <comedilib.h>
#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "temp_dir_test.hpp"

extern char** environ;

namespace {

using piezoshift::testing::slurp;

const std::string kEmulationDir = PIEZOSHIFT_COMEDI_EMULATION_DIR;
const std::string kDemoDir = PIEZOSHIFT_COMEDI_DEMO_DIR;  // empty: libcomedi-dev ships no demos

struct Outcome {
  int status = -1;  // exit status; -1: killed by a signal
  std::string out, err;
};

class ComediTools : public piezoshift::testing::TempDirTest {
 protected:
  // Runs `argv` to its end on the emulated board described by `toml`, the emulation first on
  // the library path.
  Outcome run(const std::vector<std::string>& argv, const std::string& toml = "") {
    const std::string settings = write("emulation.toml", toml);
    std::vector<std::string> env = {"LD_LIBRARY_PATH=" + kEmulationDir,
                                    "PIEZOSHIFT_COMEDI_EMULATION=" + settings};
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string v = *e;
      if (v.rfind("LD_LIBRARY_PATH=", 0) != 0 && v.rfind("PIEZOSHIFT_COMEDI_EMULATION=", 0) != 0)
        env.push_back(v);
    }
    return spawn(argv, env);
  }

  Outcome spawn(std::vector<std::string> argv, std::vector<std::string> env) {
    std::vector<char*> args, envp;
    for (auto& a : argv)
      args.push_back(a.data());
    args.push_back(nullptr);
    for (auto& e : env)
      envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, path("out").c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_addopen(&fa, 2, path("err").c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, args[0], &fa, nullptr, args.data(), envp.data());
    posix_spawn_file_actions_destroy(&fa);
    Outcome r;
    if (rc != 0) {
      ADD_FAILURE() << "cannot start " << argv[0];
      return r;
    }
    int status = 0;
    waitpid(pid, &status, 0);
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(path("out"));
    r.err = slurp(path("err"));
    return r;
  }

  static std::string demo(const std::string& name) { return kDemoDir + "/" + name; }
  void require_demos() {
    if (kDemoDir.empty())
      GTEST_SKIP() << "libcomedi-dev ships no demo sources here";
  }
  static void require(const std::string& program) {
    if (!std::filesystem::exists(program))
      GTEST_SKIP() << program << " is not installed (Debian's libcomedi0)";
  }
};

// The (version, symbol) pairs a shared library defines, from `objdump -T`: "v0.9.0 comedi_arm";
// a hidden (older) version in parentheses, as objdump prints it: "(v0.7.18) comedi_...".
std::set<std::string> exported_symbols(const std::string& library) {
  std::set<std::string> out;
  FILE* p = popen(("objdump -T " + library + " 2>/dev/null").c_str(), "r");
  if (p == nullptr)
    return out;
  char line[512];
  while (std::fgets(line, sizeof line, p) != nullptr) {
    std::istringstream in(line);
    std::vector<std::string> words;
    for (std::string w; in >> w;)
      words.push_back(w);
    // address, flags (g, DF or DO, possibly split), section, size, version, name
    if (words.size() < 5 || words.back().rfind("comedi_", 0) != 0 ||
        std::string(line).find("*UND*") != std::string::npos)
      continue;
    out.insert(words[words.size() - 2] + " " + words.back());
  }
  pclose(p);
  return out;
}

// Where the dynamic loader finds the real libcomedi.so.0 (no LD_LIBRARY_PATH in this process).
std::string real_libcomedi() {
  void* lib = dlopen("libcomedi.so.0", RTLD_LAZY | RTLD_LOCAL);
  if (lib == nullptr)
    return "";
  Dl_info info{};
  std::string file;
  if (void* f = dlsym(lib, "comedi_open"); f != nullptr && dladdr(f, &info) != 0)
    file = std::filesystem::canonical(info.dli_fname).string();
  dlclose(lib);
  return file;
}

TEST_F(ComediTools, TheEmulationExportsEverySymbolOfLibcomediAtItsVersion) {
  const std::string real = real_libcomedi();
  if (real.empty() || real.find(kEmulationDir) != std::string::npos)
    GTEST_SKIP() << "Debian's libcomedi0 is not installed";
  const std::set<std::string> want = exported_symbols(real);
  const std::set<std::string> have = exported_symbols(kEmulationDir + "/libcomedi.so.0");
  ASSERT_GE(want.size(), 104u) << "objdump -T " << real << " listed too little";
  for (const std::string& s : want)
    EXPECT_TRUE(have.count(s)) << "the emulation lacks " << s << " (of " << real << ")";
  for (const std::string& s : have)
    EXPECT_TRUE(want.count(s)) << "the emulation exports " << s << ", which " << real
                               << " does not";
}

// The library's functions beyond the tools', through dlopen of the emulation: the errors
// libcomedi and the kernel give a board without commands, the DIO and lock paths, and the older
// symbol versions a program built against libcomedi 0.7.18 or 0.9.0 binds to.
TEST_F(ComediTools, TheApiAnswersAsLibcomediAndTheKernelDo) {
  setenv("PIEZOSHIFT_COMEDI_EMULATION", write("e.toml", "").c_str(), 1);
  void* lib = dlopen((kEmulationDir + "/libcomedi.so.0").c_str(), RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(lib, nullptr) << dlerror();
  const auto f = [&](const char* name, const char* version = nullptr) {
    void* p = version != nullptr ? dlvsym(lib, name, version) : dlsym(lib, name);
    EXPECT_NE(p, nullptr) << name << "@" << (version != nullptr ? version : "default");
    return p;
  };
#define FN(type, name) reinterpret_cast<type>(f(#name))
  comedi_t* dev = FN(comedi_t * (*)(const char*), comedi_open)("/dev/comedi0");
  ASSERT_NE(dev, nullptr);
  auto comedi_errno_ = FN(int (*)(), comedi_errno);
  auto strerror_ = FN(const char* (*)(int), comedi_strerror);

  // Commands: EIO from the kernel, ECMDNOTSUPP in libcomedi's code; ENODEV past the device.
  comedi_cmd cmd{};
  auto command = FN(int (*)(comedi_t*, comedi_cmd*), comedi_command);
  EXPECT_EQ(command(dev, &cmd), -1);
  EXPECT_EQ(errno, EIO);
  EXPECT_EQ(comedi_errno_(), ECMDNOTSUPP);
  EXPECT_STREQ(strerror_(comedi_errno_()), "Command not supported");
  cmd.subdev = 14;
  EXPECT_EQ(FN(int (*)(comedi_t*, comedi_cmd*), comedi_command_test)(dev, &cmd), -1);
  EXPECT_EQ(errno, ENODEV);
  auto generic = FN(int (*)(comedi_t*, unsigned, comedi_cmd*, unsigned, unsigned),
                    comedi_get_cmd_generic_timed);
  EXPECT_EQ(generic(dev, 0, &cmd, 1, 1000), -1);
  EXPECT_EQ(errno, EIO);
  EXPECT_EQ(generic(dev, 0, &cmd, 0, 1000), -EINVAL) << "libcomedi's own return for 0 channels";
  auto old_generic = reinterpret_cast<int (*)(comedi_t*, unsigned, comedi_cmd*, unsigned)>(
      f("comedi_get_cmd_generic_timed", "v0.7.18"));
  EXPECT_EQ(old_generic(dev, 0, &cmd, 1000), -1);
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned), comedi_get_buffer_size)(dev, 0), 0);
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned), comedi_get_buffer_contents)(dev, 0), -1);
  EXPECT_EQ(errno, EINVAL);
  EXPECT_EQ(FN(int (*)(comedi_t*), comedi_get_read_subdevice)(dev), -1);

  // libcomedi's own refusals leave errno alone.
  auto flags = FN(int (*)(comedi_t*, unsigned), comedi_get_subdevice_flags);
  errno = 0;
  EXPECT_EQ(flags(dev, 14), -1);
  EXPECT_EQ(comedi_errno_(), EINVAL_SUBD);
  EXPECT_EQ(errno, 0);

  // A lock shows in the flags read now, not in the 0.7.18 version's (read at open).
  auto lock = FN(int (*)(comedi_t*, unsigned), comedi_lock);
  auto old_flags =
      reinterpret_cast<int (*)(comedi_t*, unsigned)>(f("comedi_get_subdevice_flags", "v0.7.18"));
  EXPECT_EQ(lock(dev, 0), 0);
  EXPECT_EQ(flags(dev, 0), 0x01f12000 | SDF_LOCKED | SDF_LOCK_OWNER);
  EXPECT_EQ(old_flags(dev, 0), 0x01f12000);
  EXPECT_EQ(lock(dev, 0), -1);
  EXPECT_EQ(errno, EBUSY);
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned), comedi_unlock)(dev, 0), 0);

  // DIO: direction, INSN_BITS from a base line, one line's read.
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned, unsigned, unsigned), comedi_dio_config)(dev, 2, 4,
                                                                                    COMEDI_OUTPUT),
            0);
  unsigned dir = 9;
  EXPECT_EQ(
      FN(int (*)(comedi_t*, unsigned, unsigned, unsigned*), comedi_dio_get_config)(dev, 2, 4, &dir),
      0);
  EXPECT_EQ(dir, static_cast<unsigned>(COMEDI_OUTPUT));
  unsigned bits = 0b01;
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned, unsigned, unsigned*, unsigned), comedi_dio_bitfield2)(
                dev, 2, 0b11, &bits, 4),
            0);
  EXPECT_EQ(bits & 0b11, 0b01u) << "lines 4 and 5 read back from base line 4";
  unsigned bit = 0;
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned, unsigned, unsigned*), comedi_dio_read)(dev, 2, 4, &bit),
            1);
  EXPECT_EQ(bit, 1u);
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned, unsigned, unsigned), comedi_dio_config)(dev, 0, 0,
                                                                                    COMEDI_OUTPUT),
            -1);
  EXPECT_EQ(comedi_errno_(), EINVAL_SUBD) << "AI is not a DIO subdevice";

  // AO reads back what was written; a delayed AI read is one list of three instructions.
  EXPECT_EQ(FN(int (*)(comedi_t*, unsigned, unsigned, unsigned, unsigned, lsampl_t),
               comedi_data_write)(dev, 1, 1, 0, AREF_GROUND, 40000),
            1);
  lsampl_t code = 0;
  auto read =
      FN(int (*)(comedi_t*, unsigned, unsigned, unsigned, unsigned, lsampl_t*), comedi_data_read);
  EXPECT_EQ(read(dev, 1, 1, 0, AREF_GROUND, &code), 1);
  EXPECT_EQ(code, 40000u);
  auto delayed = FN(int (*)(comedi_t*, unsigned, unsigned, unsigned, unsigned, lsampl_t*, unsigned),
                    comedi_data_read_delayed);
  EXPECT_EQ(delayed(dev, 0, 5, 0, AREF_GROUND, &code, 1000), 3);
  EXPECT_NEAR(code, 32768.0, 8.0);
  EXPECT_EQ(delayed(dev, 0, 5, 0, AREF_GROUND, &code, 100000), -1) << "INSN_WAIT takes < 100 us";
  EXPECT_EQ(errno, EINVAL);

  // Not emulated: a counter's clock (through the 0.9.0 version, channel 0), and COMEDI_TRIG.
  unsigned clock = 0, period = 0;
  auto old_clock = reinterpret_cast<int (*)(comedi_t*, unsigned, unsigned*, unsigned*)>(
      f("comedi_get_clock_source", "v0.9.0"));
  EXPECT_EQ(old_clock(dev, 11, &clock, &period), -1);
  EXPECT_EQ(errno, EINVAL);
  comedi_sv_t sv{};
  EXPECT_EQ(
      FN(int (*)(comedi_sv_t*, comedi_t*, unsigned, unsigned), comedi_sv_init)(&sv, dev, 0, 5), 0);
  EXPECT_EQ(sv.maxdata, 0xffffu);
  double v = 0.0;
  EXPECT_EQ(FN(int (*)(comedi_sv_t*, double*), comedi_sv_measure)(&sv, &v), -1);
  EXPECT_EQ(comedi_errno_(), ENOTTY);

  // The descriptor: no data, no writing.
  const int fd = FN(int (*)(comedi_t*), comedi_fileno)(dev);
  char buf[8];
  EXPECT_EQ(::read(fd, buf, sizeof buf), 0);
  EXPECT_EQ(::write(fd, buf, 1), -1);
  EXPECT_EQ(errno, EBADF);

  // Codes at either end of a range read NaN once asked to.
  auto oor = FN(comedi_oor_behavior(*)(comedi_oor_behavior), comedi_set_global_oor_behavior);
  auto to_phys = FN(double (*)(lsampl_t, comedi_range*, lsampl_t), comedi_to_phys);
  comedi_range r{-10.0, 10.0, UNIT_volt};
  EXPECT_EQ(to_phys(0, &r, 65535), -10.0);
  EXPECT_EQ(oor(COMEDI_OOR_NAN), COMEDI_OOR_NUMBER);
  EXPECT_TRUE(std::isnan(to_phys(0, &r, 65535)));
  EXPECT_DOUBLE_EQ(to_phys(32768, &r, 65535), 20.0 * 32768 / 65535 - 10.0);
#undef FN
  EXPECT_EQ(reinterpret_cast<int (*)(comedi_t*)>(f("comedi_close"))(dev), 0);
  dlclose(lib);
  unsetenv("PIEZOSHIFT_COMEDI_EMULATION");
}

// comedi_board_info's report of a PCI-6229 as ni_pcimio attaches it without an interrupt line:
// the 14 subdevices of ni_mio_common.c's ni_E_init with their flags, channels, maxdata and
// ranges (range_digital and range_unknown: [0, 1] V), and no commands.
const char* const kBoardInfo = R"(overall info:
  version code: 0x00074c
  driver name: ni_pcimio
  board name: pci-6229
  number of subdevices: 14
subdevice 0:
  type: 1 (analog input)
  flags: 0x01f12000
  number of channels: 32
  max data value: 65535
  ranges:
    all chans: [-10 V,10 V] [-5 V,5 V] [-1 V,1 V] [-0.2 V,0.2 V]
  command:
    not supported
subdevice 1:
  type: 2 (analog output)
  flags: 0x02122000
  number of channels: 4
  max data value: 65535
  ranges:
    all chans: [-10 V,10 V]
  command:
    not supported
subdevice 2:
  type: 5 (digital I/O)
  flags: 0x10030000
  number of channels: 32
  max data value: 1
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 3:
  type: 0 (unused)
subdevice 4:
  type: 0 (unused)
subdevice 5:
  type: 9 (calibration)
  flags: 0x00040000
  number of channels: 1
  max data value: 0
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 6:
  type: 8 (memory)
  flags: 0x00050000
  number of channels: 1024
  max data value: 255
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 7:
  type: 5 (digital I/O)
  flags: 0x00070000
  number of channels: 16
  max data value: 1
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 8:
  type: 0 (unused)
subdevice 9:
  type: 11 (serial digital I/O)
  flags: 0x00070000
  number of channels: 1
  max data value: 255
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 10:
  type: 5 (digital I/O)
  flags: 0x00070000
  number of channels: 8
  max data value: 1
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 11:
  type: 6 (counter)
  flags: 0x10030000
  number of channels: 3
  max data value: 4294967295
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 12:
  type: 6 (counter)
  flags: 0x10030000
  number of channels: 3
  max data value: 4294967295
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
subdevice 13:
  type: 6 (counter)
  flags: 0x00030000
  number of channels: 1
  max data value: 15
  ranges:
    all chans: [0 V,1 V]
  command:
    not supported
)";

TEST_F(ComediTools, BoardInfoReportsThePci6229) {
  require("/usr/bin/comedi_board_info");
  const Outcome r = run({"/usr/bin/comedi_board_info"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, kBoardInfo);
  EXPECT_EQ(r.err, "");
}

TEST_F(ComediTools, BoardInfoNamesAMissingDevice) {
  require("/usr/bin/comedi_board_info");
  const Outcome r = run({"/usr/bin/comedi_board_info", "/dev/comedi3"});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "/dev/comedi3: No such file or directory\n");
}

TEST_F(ComediTools, BoardInfoOfAPci6220HasNoAnalogOutput) {
  require("/usr/bin/comedi_board_info");
  const Outcome r = run({"/usr/bin/comedi_board_info"}, "[board]\nmodel = \"pci-6220\"\n");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("  board name: pci-6220\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("subdevice 0:\n  type: 1 (analog input)\n  flags: 0x01f12000\n"
                       "  number of channels: 16\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("subdevice 1:\n  type: 0 (unused)\nsubdevice 2:\n  type: 5 (digital I/O)\n"
                       "  flags: 0x10030000\n  number of channels: 8\n"),
            std::string::npos)
      << r.out;
}

// One subdevice's part of comedi_test's report (from "I: subdevice N" to the next).
std::string subdevice_report(const std::string& out, int subdevice) {
  const std::string head = "I: subdevice " + std::to_string(subdevice) + "\n";
  const std::size_t from = out.find(head);
  if (from == std::string::npos)
    return "";
  const std::size_t to = out.find("I:\nI: subdevice ", from);
  return out.substr(from, to == std::string::npos ? std::string::npos : to - from);
}

TEST_F(ComediTools, ComediTestRunsEveryTestOnEverySubdevice) {
  require("/usr/bin/comedi_test");
  const Outcome r = run({"/usr/bin/comedi_test"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("I: Comedi version: 0.7.76\nI: Comedilib version: unknown =)\n"
                       "I: driver name: ni_pcimio\nI: device name: pci-6229\n"),
            std::string::npos)
      << r.out;
  // Every subdevice: no command (cmd_no_cmd's EIO, the other command tests not applicable), and
  // no buffer (bufconfig's size 0).
  for (int s = 0; s < 14; ++s) {
    const std::string rep = subdevice_report(r.out, s);
    SCOPED_TRACE("subdevice " + std::to_string(s) + ":\n" + rep);
    EXPECT_NE(rep.find("I: testing cmd_no_cmd...\ngot EIO, good\n"), std::string::npos);
    for (const char* t : {"cmd_probe_src_mask", "cmd_probe_fast_1chan", "cmd_read_fast_1chan",
                          "cmd_write_fast_1chan", "cmd_logic_bug", "cmd_fifo_depth_check",
                          "cmd_start_inttrig", "mmap", "read_select"})
      EXPECT_NE(rep.find("I: testing " + std::string(t) + "...\nnot applicable\n"),
                std::string::npos)
          << t;
    EXPECT_NE(rep.find("I: testing bufconfig...\nbuffer length is 0, good\n"), std::string::npos);
  }
  // The emulated subdevices read one sample, and none with n = 0.
  for (int s : {0, 1, 2}) {
    const std::string rep = subdevice_report(r.out, s);
    SCOPED_TRACE(rep);
    EXPECT_NE(rep.find("I: testing insn_read...\nrev 1\ncomedi_do_insn returned 1, good\n"),
              std::string::npos);
    EXPECT_NE(rep.find("I: testing insn_read_0...\ncomedi_do_insn returned 0, good\n"),
              std::string::npos);
    EXPECT_NE(rep.find("I: testing insn_read_time...\nrev 1\ncomedi_do_insn: 3\n"),
              std::string::npos);
  }
  EXPECT_NE(subdevice_report(r.out, 0).find("  number of channels: 32\n  max data value: 65535\n"
                                            "  ranges:\n    all chans: [-10,10] [-5,5] [-1,1] "
                                            "[-0.2,0.2]\n"),
            std::string::npos);
  // The unused subdevices refuse instructions with EIO, as the kernel does.
  for (int s : {3, 4, 8})
    EXPECT_NE(subdevice_report(r.out, s).find("I: testing insn_read...\nrev 1\n"
                                              "comedi_do_insn: EIO, good\n"),
              std::string::npos)
        << subdevice_report(r.out, s);
  // The subdevices not emulated refuse a read with EINVAL: the calibration PWM and the serial
  // port have no read on a real board either; the EEPROM, PFI, RTSI and counters do.
  for (int s : {5, 6, 7, 9, 10, 11, 12, 13}) {
    const std::string rep = subdevice_report(r.out, s);
    EXPECT_NE(rep.find("I: testing insn_read...\nrev 1\nE: comedi_do_insn: Invalid argument\n"),
              std::string::npos)
        << rep;
    EXPECT_NE(rep.find("comedi_do_insn: -1\nW: comedi_do_insn: errno=22 Invalid argument\n"),
              std::string::npos)
        << rep;
  }
  EXPECT_EQ(r.err, "");
}

TEST_F(ComediTools, DemoBoardInfoListsTheSubdevices) {
  require_demos();
  const Outcome r = run({demo("board_info")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("overall info:\n  version code: 0x00074c\n  driver name: ni_pcimio\n"
                       "  board name: pci-6229\n  number of subdevices: 14\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("subdevice 0:\n  type: 1 (analog input)\n  flags: 0x01f12000\n"
                       "  number of channels: 32\n  max data value: 65535\n  ranges:\n"
                       "    all chans: [-10,10] [-5,5] [-1,1] [-0.2,0.2]\n  command:\n"
                       "    not supported\n"),
            std::string::npos)
      << r.out;
}

TEST_F(ComediTools, DemoInpReadsAChannelRawAndInVolts) {
  require_demos();
  // AI 5 has nothing on it: 0 V, a few codes off mid-scale (the uncalibrated converter).
  const Outcome raw = run({demo("inp"), "-s", "0", "-c", "5"});
  ASSERT_EQ(raw.status, 0) << raw.err;
  const long code = std::stol(raw.out);
  EXPECT_NEAR(code, 32768, 8) << raw.out;
  const Outcome volts = run({demo("inp"), "-p", "-s", "0", "-c", "5", "-r", "3"});
  ASSERT_EQ(volts.status, 0) << volts.err;
  ASSERT_EQ(volts.out.substr(volts.out.size() - 3), " V\n") << volts.out;
  EXPECT_NEAR(std::stod(volts.out), 0.0, 1e-4) << volts.out;  // +-0.2 V: 6 uV a code
  // The unused subdevice 3, and a channel AI does not have.
  const Outcome unused = run({demo("inp"), "-s", "3"});
  EXPECT_EQ(unused.status, 255);
  EXPECT_EQ(unused.err, "/dev/comedi0: Input/output error\n");
  const Outcome channel = run({demo("inp"), "-s", "0", "-c", "32"});
  EXPECT_EQ(channel.status, 255);
  EXPECT_EQ(channel.err, "/dev/comedi0: Invalid argument\n");
}

TEST_F(ComediTools, DemoOutpWritesAnOutputAndRefusesWhatTheDriverRefuses) {
  require_demos();
  const Outcome ok = run({demo("outp"), "-s", "1", "-c", "0", "40000"});
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(ok.out, "40000\n");
  const Outcome high = run({demo("outp"), "-s", "1", "-c", "0", "65536"});  // above maxdata
  EXPECT_EQ(high.status, 255);
  EXPECT_EQ(high.err, "/dev/comedi0: Invalid argument\n");
  const Outcome input = run({demo("outp"), "-s", "0", "-c", "0", "100"});  // AI has no write
  EXPECT_EQ(input.status, 255);
  EXPECT_EQ(input.err, "/dev/comedi0: Invalid argument\n");
  const Outcome channel = run({demo("outp"), "-s", "1", "-c", "4", "100"});  // AO has 0..3
  EXPECT_EQ(channel.status, 255);
  EXPECT_EQ(channel.err, "/dev/comedi0: Invalid channel\n");  // libcomedi's own check
}

TEST_F(ComediTools, DemoInsnReadsSamplesBetweenTwoTimestamps) {
  require_demos();
  const Outcome r = run({demo("insn"), "-s", "0", "-c", "5", "-N", "4"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream in(r.out);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("initial time: ", 0), 0u) << r.out;
  for (int i = 0; i < 4; ++i) {
    std::getline(in, line);
    EXPECT_NEAR(std::stol(line), 32768, 8) << r.out;
  }
  std::getline(in, line);
  EXPECT_EQ(line.rfind("final time: ", 0), 0u) << r.out;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("difference (us): ", 0), 0u) << r.out;
  EXPECT_GE(std::stol(line.substr(17)), 0) << r.out;
}

TEST_F(ComediTools, DemoApplyCalNeedsTheCalibrationFile) {
  require_demos();
  // An M Series file holds polynomials only: nothing to write to the board, success.
  const Outcome ok = run({demo("apply_cal"), "-s", "0", "-c", "0"});
  EXPECT_EQ(ok.status, 0);
  EXPECT_EQ(ok.out + ok.err, "");
  // comedi_soft_calibrate never run: the default file does not exist (the demo exits 0).
  const Outcome none = run({demo("apply_cal"), "-s", "0"}, "[board]\ncalibrated = false\n");
  EXPECT_EQ(none.status, 0);
  EXPECT_EQ(none.err, "/dev/comedi0: No such file or directory\n");
}

TEST_F(ComediTools, DemoCmdFindsNoSubdeviceTakingCommands) {
  require_demos();
  const Outcome r = run({demo("cmd")});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "defaulted to subdevice 0\nsubdevice 0 does not support 'read' commands\n");
  EXPECT_EQ(r.out, "");
}

}  // namespace
