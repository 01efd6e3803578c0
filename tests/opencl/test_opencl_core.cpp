// Parity on the device: Core actions, integrators, sub-steps and the NaN guard on the device.
// Each test runs the same build on the CPU and on the device (tests/opencl/parity.hpp).
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;
