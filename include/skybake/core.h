// skybake/core.h: build facts, threading and logging controls.
#pragma once

#include <string>

#include "skybake/version.h"

namespace skybake {

// "0.1.0"
const char* version();
// True when this build compiled the CUDA backends (a GPU may still be absent).
bool build_has_cuda();
// Number of CUDA devices usable now; 0 without CUDA, without a GPU, or when
// the CUDA runtime cannot talk to the driver (cuda_device_problem() says why).
int cuda_device_count();
// Why cuda_device_count() is 0, in one line: "this build has no CUDA support",
// or the CUDA runtime's error name and text (cudaErrorNoDevice,
// cudaErrorInsufficientDriver for a missing or old driver,
// cudaErrorSystemDriverMismatch, ...). Empty when a device is usable.
std::string cuda_device_problem();
// Name of the selected CUDA device (cuda_device_index()), or an empty string.
std::string cuda_device_name();
// The CUDA device that the GPU backends use: 0 unless set, e.g. to a rank's
// local index among the processes on its node (skybake/distributed.h).
// Taken modulo cuda_device_count() when used.
void set_cuda_device_index(int index);
int cuda_device_index();
// Makes the selected device current on the calling thread (CUDA keeps one per
// host thread); does nothing in a build without CUDA or without a device.
void use_cuda_device_on_this_thread();
// Throws skybake::Error, naming `where` (e.g. "--device cuda"), when this
// build has no CUDA support or no CUDA device is present.
void require_cuda_device(const std::string& where);

// Where batch work runs.
enum class Device : int { Cpu = 0, Cuda = 1 };
// "cpu" or "cuda"; throws skybake::Error naming `where` otherwise.
Device parse_device(const std::string& name, const std::string& where = "device");
const char* device_name(Device device); // "cpu", "cuda"

// Limits the worker threads used by parallel loops; 0 restores the default
// (all hardware threads). Results do not depend on the thread count.
void set_thread_count(int threads);
int thread_count();

// Quiet mode suppresses progress bars and informational messages on stderr.
void set_quiet(bool quiet);
bool quiet();

} // namespace skybake
