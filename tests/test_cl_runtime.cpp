// The OpenCL runtime: device specs, every device found, kernels built once and cached, build
// failures that name the device and carry the log, and the triad kernel against its reference.
// Tests marked "per device" run once for every OpenCL device present (PoCL here, a GPU elsewhere).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "cl/cl_runtime.h"
#include "opencl_test_support.h"
#include "cl/embedded_kernels.h"
#include "core/error.h"
#include "perf/bandwidth.h"
#include "seed_support.h"

using namespace pneumo;

TEST(DeviceSpec, ParsesTheThreeForms) {
  EXPECT_FALSE(ocl::parse_device_spec("cpu").use_opencl);
  auto first = ocl::parse_device_spec("opencl");
  EXPECT_TRUE(first.use_opencl);
  EXPECT_EQ(first.platform, -1);
  auto given = ocl::parse_device_spec("opencl:1:2");
  EXPECT_EQ(given.platform, 1);
  EXPECT_EQ(given.device, 2);
}

// "auto": a GPU or accelerator wherever it is listed, the C++ reference where only CPU devices (PoCL,
// on the reference's own cores) or none are.
TEST(DeviceSpec, AutoPicksTheFirstGpuOrAcceleratorElseTheReference) {
  auto device = [](int p, int d, const char* type) {
    ocl::DeviceInfo i;
    i.platform_index = p;
    i.device_index = d;
    i.type = type;
    return i;
  };
  EXPECT_EQ(ocl::auto_device({}), "cpu");
  EXPECT_EQ(ocl::auto_device({device(0, 0, "cpu")}), "cpu");
  EXPECT_EQ(ocl::auto_device({device(0, 0, "cpu"), device(1, 0, "gpu"), device(1, 1, "gpu")}), "opencl:1:0");
  EXPECT_EQ(ocl::auto_device({device(0, 0, "cpu"), device(0, 1, "accelerator")}), "opencl:0:1");
  EXPECT_EQ(ocl::auto_device({device(0, 0, "other")}), "cpu");
  // On this machine: the choice for the devices listed here, named in the spec's text.
  const ocl::DeviceSpec chosen = ocl::parse_device_spec("auto");
  const std::string expected = ocl::auto_device(ocl::list_devices());
  EXPECT_EQ(chosen.text, expected);
  EXPECT_EQ(chosen.use_opencl, expected != "cpu");
}

TEST(DeviceSpec, RejectsAnythingElseWithTheAllowedForms) {
  for (const char* bad : {"gpu", "opencl:", "opencl:0", "opencl:a:b", "OpenCL", "", "opencl:0:0:0"}) {
    try {
      ocl::parse_device_spec(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("opencl:P:D"), std::string::npos) << e.what();
    }
  }
}

// CI and this machine have PoCL; a machine without any OpenCL device must say so explicitly
// (PNEUMO_ALLOW_NO_OPENCL=1) rather than skip every per-device test in silence.
TEST(OpenCL, AtLeastOneDeviceIsPresent) {
  if (std::getenv("PNEUMO_ALLOW_NO_OPENCL")) GTEST_SKIP() << "PNEUMO_ALLOW_NO_OPENCL is set";
  EXPECT_FALSE(ocl::list_devices().empty()) << ocl::no_device_hint();
}

TEST(OpenCL, MissingDeviceIsAnInputErrorListingTheDevices) {
  try {
    ocl::Context::open(ocl::parse_device_spec("opencl:99:0"));
    FAIL() << "opened a device that does not exist";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("opencl:99:0"), std::string::npos) << e.what();
  }
}

TEST(EmbeddedKernels, EveryKernelFileIsEmbedded) {
  const auto& table = ocl::embedded_kernels();
  ASSERT_FALSE(table.empty());
  bool found = false;
  for (const auto& k : table) {
    EXPECT_FALSE(k.source.empty()) << k.path;
    found |= std::string(k.path) == "stream_triad.cl";
  }
  EXPECT_TRUE(found);
  EXPECT_THROW(ocl::kernel_source("no_such_kernel.cl"), std::runtime_error);
}

TEST(OpenCL, MissingFeaturesAreNamed) {
  ocl::DeviceInfo d;
  d.platform_index = 0;
  d.device_index = 1;
  d.name = "Old Device";
  d.opencl_c_version = "OpenCL C 1.1 ";
  d.max_work_group_size = 32;
  d.local_mem_bytes = 512;
  const std::string missing = ocl::missing_features(d, 64, 1024);
  EXPECT_NE(missing.find("OpenCL C 1.2"), std::string::npos) << missing;
  EXPECT_NE(missing.find("work-groups of 64"), std::string::npos) << missing;
  EXPECT_NE(missing.find("1024 bytes of local memory"), std::string::npos) << missing;
  try {
    ocl::require_features(d, 64, 1024);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("opencl:0:1 (Old Device)"), std::string::npos) << e.what();
  }
  d.opencl_c_version = "OpenCL C 3.0 PoCL";
  d.max_work_group_size = 4096;
  d.local_mem_bytes = 1 << 20;
  EXPECT_EQ(ocl::missing_features(d, 64, 1024), "");
  for (const auto& real : ocl::list_devices()) EXPECT_EQ(ocl::missing_features(real, 64, 1024), "") << real.name;
}

class PerDevice : public ::testing::TestWithParam<std::string> {
 protected:
  std::shared_ptr<ocl::Context> ctx() { return ocl::Context::shared(ocl::parse_device_spec(GetParam())); }
};

// Triad against its reference on random input. Tolerance: 1 ulp of the result's magnitude, because
// OpenCL C may contract b + s*c into one fma (FP_CONTRACT is on by default) while the host may not.
TEST_P(PerDevice, TriadKernelMatchesReference) {
  auto c = ctx();
  const unsigned seed = testing_support::test_seed(20261209u);
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1e3f, 1e3f);
  const std::size_t n = 100003;   // not a multiple of the work-group size
  std::vector<float> b(n), cc(n), ref(n), out(n);
  for (std::size_t i = 0; i < n; ++i) { b[i] = u(rng); cc[i] = u(rng); }
  const float s = u(rng);
  perf::triad_ref(ref.data(), b.data(), cc.data(), s, n);

  cl::Buffer da(c->context(), CL_MEM_WRITE_ONLY, n * sizeof(float));
  cl::Buffer db(c->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, n * sizeof(float), b.data());
  cl::Buffer dc(c->context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, n * sizeof(float), cc.data());
  cl::Kernel k = c->kernel("stream_triad.cl", "stream_triad");
  k.setArg(0, da); k.setArg(1, db); k.setArg(2, dc); k.setArg(3, s); k.setArg(4, cl_uint(n));
  c->queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange((n + 63) / 64 * 64), cl::NDRange(64));
  c->queue().enqueueReadBuffer(da, CL_TRUE, 0, n * sizeof(float), out.data());
  for (std::size_t i = 0; i < n; ++i) {
    const float tol = std::nextafter(std::abs(b[i]) + std::abs(s * cc[i]), INFINITY) - (std::abs(b[i]) + std::abs(s * cc[i]));
    ASSERT_LE(std::abs(out[i] - ref[i]), tol) << "element " << i;
  }
}

TEST_P(PerDevice, ProgramsAreBuiltOnceAndCached) {
  auto c = ctx();
  cl::Program& p1 = c->program({"stream_triad.cl"});
  cl::Program& p2 = c->program({"stream_triad.cl"});
  EXPECT_EQ(&p1, &p2);
  cl::Program& p3 = c->program({"stream_triad.cl"}, "-DUNUSED_OPTION=1");
  EXPECT_NE(&p1, &p3);   // other options, other binary
}

TEST_P(PerDevice, BuildFailureNamesTheDeviceAndCarriesTheLog) {
  auto c = ctx();
  try {
    c->program_from_source("broken.cl", "__kernel void k(__global float* x) { x[0] = undeclared_name; }");
    FAIL() << "a broken kernel built";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("broken.cl"), std::string::npos) << msg;
    EXPECT_NE(msg.find(c->info().name), std::string::npos) << msg;
    EXPECT_NE(msg.find("build log"), std::string::npos) << msg;
    EXPECT_NE(msg.find("undeclared_name"), std::string::npos) << msg;
  }
}

TEST_P(PerDevice, IncludesAreExpandedFromEmbeddedKernels) {
  auto c = ctx();
  const std::string src = "#include \"stream_triad.cl\"\n__kernel void twice(__global float* x) { x[0] *= 2.0f; }\n";
  cl::Program& p = c->program_from_source("with_include.cl", ocl::expand_includes(src, "with_include.cl"));
  EXPECT_NO_THROW(cl::Kernel(p, "stream_triad"));
  EXPECT_NO_THROW(cl::Kernel(p, "twice"));
  EXPECT_THROW(ocl::expand_includes("#include \"missing.cl\"\n", "x.cl"), std::runtime_error);
}

TEST_P(PerDevice, ACaseTooLargeIsRefusedBeforeAllocatingWithTheEstimate) {
  // Compared: the message against the estimate passed in and the device's limit, both in MiB rounded
  // up, for a case larger than the device's memory and for one buffer larger than it allows.
  // (DeviceMemoryEstimate checks that the estimates cover what is then allocated.)
  auto c = ctx();
  auto mib = [](uint64_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; };
  const uint64_t too_much = c->info().global_mem_bytes + (1ull << 30) + 12345;
  try {
    c->check_fits(too_much, 1 << 20, "the test case");
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(c->info().name), std::string::npos) << msg;
    EXPECT_NE(msg.find("the test case needs about " + mib(too_much)), std::string::npos) << msg;
    EXPECT_NE(msg.find(mib(c->info().global_mem_bytes)), std::string::npos) << msg;
  }
  const uint64_t too_large_buffer = c->info().max_alloc_bytes + (3u << 20);
  try {
    c->check_fits(too_large_buffer, too_large_buffer, "one buffer");
    FAIL();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("one buffer needs a single buffer of " + mib(too_large_buffer)), std::string::npos) << msg;
    EXPECT_NE(msg.find(mib(c->info().max_alloc_bytes)), std::string::npos) << msg;
  }
  EXPECT_NO_THROW(c->check_fits(1 << 20, 1 << 20, "a small case"));
}

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(PerDevice);
INSTANTIATE_TEST_SUITE_P(OpenCL, PerDevice, ::testing::ValuesIn(testing_support::opencl_device_specs()),
                         [](const auto& info) { return testing_support::spec_name(info.param); });
