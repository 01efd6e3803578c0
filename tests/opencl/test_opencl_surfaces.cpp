// Parity on the device: Deflectors, absorbers, blockers, 2-D and neighbour actions
// (kernels/surfaces.cl). Each test runs the same build on the CPU and on the device
// (tests/opencl/parity.hpp).
#include "parity.hpp"

using namespace flurry;
using namespace flurry::test;
