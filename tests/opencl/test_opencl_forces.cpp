// Parity on the device: Forces, random and target actions, curves over life (kernels/forces.cl).
// Each test runs the same build on the CPU and on the device (tests/opencl/parity.hpp).
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;
