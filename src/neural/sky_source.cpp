// The sky source: what evaluates the sky, and where (skybake/sky_source.h).
#include "skybake/sky_source.h"

#include <optional>

#include "skybake/error.h"

namespace skybake {

struct SkySource::Impl {
    SkyModel model;
    SkyMethod method = SkyMethod::Tables;
    Device device = Device::Cpu;
    std::optional<NeuralSky> net;
};

SkySource::SkySource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SkySource::SkySource(SkySource&&) noexcept = default;
SkySource& SkySource::operator=(SkySource&&) noexcept = default;
SkySource::~SkySource() = default;

SkySource SkySource::reference(SkyModel model, SkyMethod method, Device device) {
    if (device == Device::Cuda) {
        if (method == SkyMethod::Exact)
            throw Error("the exact method runs on the CPU only; use the CPU or the tables method", "device");
        require_cuda_device("device");
    }
    return SkySource(std::make_unique<Impl>(Impl{std::move(model), method, device, std::nullopt}));
}

SkySource SkySource::network(NeuralSky net, Device device) {
    if (device == Device::Cuda)
        require_cuda_device("device");
    SkyModel model = neural_reference_model(net);
    return SkySource(std::make_unique<Impl>(Impl{std::move(model), SkyMethod::Tables, device, std::move(net)}));
}

const char* SkySource::method_name() const {
    if (impl_->net)
        return "neural";
    return impl_->method == SkyMethod::Exact ? "exact" : "tables";
}

Device SkySource::device() const { return impl_->device; }
bool SkySource::is_network() const { return impl_->net.has_value(); }
const Atmosphere& SkySource::atmosphere() const { return impl_->model.atmosphere(); }
const SkyModel& SkySource::tables() const { return impl_->model; }

const NeuralSky& SkySource::network_weights() const {
    if (!impl_->net)
        throw Error("this sky source is the reference model, not a network", "network");
    return *impl_->net;
}

void SkySource::evaluate(std::span<const SkySample> samples, std::span<glm::vec3> out) const {
    const bool gpu = impl_->device == Device::Cuda;
    if (impl_->net)
        gpu ? evaluate_neural_sky_cuda(*impl_->net, samples, out) : evaluate_neural_sky(*impl_->net, samples, out);
    else if (gpu)
        evaluate_sky_cuda(impl_->model, samples, out);
    else
        evaluate_sky(impl_->model, samples, out, impl_->method);
}

Image SkySource::render(const SkyRenderSettings& settings) const {
    const bool gpu = impl_->device == Device::Cuda;
    if (impl_->net)
        return gpu ? render_neural_sky_cuda(*impl_->net, impl_->model, settings)
                   : render_neural_sky(*impl_->net, impl_->model, settings);
    SkyRenderSettings s = settings;
    s.method = impl_->method;
    return gpu ? render_sky_cuda(impl_->model, s) : render_sky(impl_->model, s);
}

} // namespace skybake
