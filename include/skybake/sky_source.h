// skybake/sky_source.h: the one object that says what computes the sky and
// where: the reference model (the seed's sum over its optical-length tables,
// or the exact quadrature) or a trained network, on the CPU or on a CUDA GPU.
// The CLI's sky commands, the renderers and the Python module all evaluate
// and render through it, so the choice is made once, here.
//
//   SkySource sky = SkySource::network(load_neural_sky("w.json"), Device::Cuda);
//   sky.evaluate(samples, radiance);        // 1/sr per unit sun irradiance
//   Image img = sky.render(settings);       // linear radiance
#pragma once

#include <memory>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include "skybake/core.h"
#include "skybake/image.h"
#include "skybake/neural.h"
#include "skybake/sky.h"

namespace skybake {

class SkySource {
public:
    // The reference model of `model`'s atmosphere. Throws skybake::Error
    // (where: "device") for the exact method on CUDA (it runs on the CPU only)
    // and for CUDA in a build without it or on a machine without a GPU.
    static SkySource reference(SkyModel model, SkyMethod method = SkyMethod::Tables, Device device = Device::Cpu);
    // A trained network; the ground, the sun and the planet's shadow come from
    // the tables of its reference model (neural_reference_model()). Throws as
    // reference() for CUDA.
    static SkySource network(NeuralSky net, Device device = Device::Cpu);

    SkySource(SkySource&&) noexcept;
    SkySource& operator=(SkySource&&) noexcept;
    ~SkySource();

    // "tables", "exact" or "neural".
    const char* method_name() const;
    Device device() const;
    bool is_network() const;
    const Atmosphere& atmosphere() const;
    // The tables behind the ground and the sun (the network's reference model).
    const SkyModel& tables() const;
    // The network (is_network() only).
    const NeuralSky& network_weights() const;

    // Radiance of each sample; out.size() == samples.size(); samples valid.
    void evaluate(std::span<const SkySample> samples, std::span<glm::vec3> out) const;
    // render_sky() / render_neural_sky() on this source's device.
    Image render(const SkyRenderSettings& settings) const;

private:
    struct Impl;
    explicit SkySource(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace skybake
