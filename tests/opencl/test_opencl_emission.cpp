// Parity on the device: Emission on the device: every domain, spacing, normal speed, prime
// emitters. Each test runs the same build on the CPU and on the device (tests/opencl/parity.hpp).
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;
