// Issue 27 §2: outputs are never lost or clobbered. Two outputs on one file and an output onto a
// file the command reads are refused (exit 2, even with --force); a failing command leaves none of
// its outputs behind; a failed write (a full device, standard output included) is exit 4.
#include <gmock/gmock.h>

#include "cli_support.hpp"

namespace servotwin::cli_test {
namespace {

using ::testing::HasSubstr;

class Outputs : public Cli {};

constexpr const char* kProgram = "G21 G90\nG01 X10 F600\nM30\n";

TEST_F(Outputs, TwoOutputsOnOneFileAreRefused) {
  Result r = run("frf measure --plant motor-bench -o x.csv --trace x.csv");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("'x.csv'"));
  EXPECT_THAT(r.err, HasSubstr("--trace"));
  EXPECT_FALSE(fs::exists(path("x.csv")));
  // The same file under two spellings; --force changes nothing.
  fs::create_directory(path("d"));
  r = run("--force tune motor-bench -o d/c.json --report ./d/../d/c.json");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--report"));
  EXPECT_FALSE(fs::exists(path("d/c.json")));
  // Standard output twice.
  r = run("tune motor-bench -o - --report /dev/stdout");
  EXPECT_EQ(r.status, 2) << r.err;
}

TEST_F(Outputs, AnOutputOntoAnInputIsRefusedEvenWithForce) {
  write("a.nc", kProgram);
  for (const char* args : {"interpolate -p a.nc -o a.nc", "--force interpolate -p a.nc -o a.nc",
                           "--force interpolate -p ./a.nc -o a.nc"}) {
    const Result r = run(args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr("--program")) << args;
    EXPECT_EQ(slurp(path("a.nc")), kProgram) << args;
  }
  // Through a symbolic link: the same device and inode.
  fs::create_symlink("a.nc", path("link.nc"));
  const Result r = run("--force interpolate -p a.nc -o link.nc");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(slurp(path("a.nc")), kProgram);
  EXPECT_TRUE(fs::is_symlink(path("link.nc")));
  // A different file is fine, and devices are written in place without --force.
  EXPECT_EQ(run("interpolate -p a.nc -o b.csv").status, 0);
  EXPECT_EQ(run("interpolate -p a.nc -o /dev/null").status, 0);
  EXPECT_EQ(run("interpolate -p a.nc -o /dev/null --force").status, 0);
}

TEST_F(Outputs, AFailingCommandLeavesNoOutputBehind) {
  // tune writes its controller, then its report fails on the full device: the controller, already
  // complete in its temporary file, is not moved into place, and nothing else is left in the folder.
  const Result r = run("tune motor-bench -o c.json --report /dev/full");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_THAT(r.err, HasSubstr("/dev/full (--report)"));
  EXPECT_FALSE(fs::exists(path("c.json")));
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_THAT(entry.path().filename().string(), ::testing::StartsWith("std")) << entry.path();
}

TEST_F(Outputs, WriteErrorsAreExit4) {
  write("a.nc", kProgram);
  Result r = run("capture --machine fadal-pid -p a.nc -o /dev/full");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_THAT(r.err, HasSubstr("/dev/full (-o)"));
  r = run("capture --machine fadal-pid -p a.nc -o -", "/dev/full");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_THAT(r.err, HasSubstr("standard output"));
  // A command whose result is printed, not written to a file.
  r = run("machine fadal-pid", "/dev/full");
  EXPECT_EQ(r.status, 4) << r.err;
  // The same commands succeed where the writes arrive.
  EXPECT_EQ(run("capture --machine fadal-pid -p a.nc -o -").status, 0);
  EXPECT_EQ(run("machine fadal-pid").status, 0);
}

}  // namespace
}  // namespace servotwin::cli_test
