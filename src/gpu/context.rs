//! Adapter and device: find adapters, pick one (`--adapter NAME`, or the
//! best real GPU for `--backend auto`), and open a device with the
//! features and limits the solver needs.

use crate::error::{Error, Result};

/// One adapter as `lme-mpm info` shows it.
#[derive(Debug, Clone)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: String,
    pub device_type: wgpu::DeviceType,
    pub driver: String,
    pub float_atomics: bool,
    pub max_storage_buffer_binding_size: u64,
    pub max_buffer_size: u64,
    pub max_storage_buffers_per_shader_stage: u32,
    pub max_compute_workgroups_per_dimension: u32,
}

impl AdapterSummary {
    fn of(a: &wgpu::Adapter) -> Self {
        let i = a.get_info();
        let l = a.limits();
        AdapterSummary {
            name: i.name,
            backend: format!("{:?}", i.backend),
            device_type: i.device_type,
            driver: format!("{} {}", i.driver, i.driver_info).trim().to_string(),
            float_atomics: a.features().contains(wgpu::Features::SHADER_FLOAT32_ATOMIC),
            max_storage_buffer_binding_size: l.max_storage_buffer_binding_size,
            max_buffer_size: l.max_buffer_size,
            max_storage_buffers_per_shader_stage: l.max_storage_buffers_per_shader_stage,
            max_compute_workgroups_per_dimension: l.max_compute_workgroups_per_dimension,
        }
    }

    /// A software rasteriser (llvmpipe, WARP, SwiftShader): correct but slower than the CPU path.
    pub fn is_software(&self) -> bool {
        self.device_type == wgpu::DeviceType::Cpu
    }

    /// One line for messages: "NVIDIA H100 (Vulkan, DiscreteGpu)".
    pub fn label(&self) -> String {
        format!("{} ({}, {:?})", self.name, self.backend, self.device_type)
    }
}

/// How scatters add floats: native `atomic<f32>` or a compare-exchange loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AtomicMode {
    /// `atomicAdd` on `atomic<f32>` (needs SHADER_FLOAT32_ATOMIC).
    Float,
    /// `atomicCompareExchangeWeak` on `atomic<u32>` holding f32 bits: any adapter.
    CompareExchange,
}

/// An open device and what was chosen for it.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: AdapterSummary,
    pub atomics: AtomicMode,
    pub limits: wgpu::Limits,
}

fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    // Vulkan, Metal and DX12 unless WGPU_BACKEND says otherwise: the GL
    // backend's compute support is partial and it wants a display.
    if std::env::var_os("WGPU_BACKEND").is_none() {
        desc.backends = wgpu::Backends::PRIMARY;
    }
    wgpu::Instance::new(desc)
}

/// Every adapter wgpu can see (possibly none).
pub fn adapters() -> Vec<AdapterSummary> {
    let inst = instance();
    pollster::block_on(inst.enumerate_adapters(wgpu::Backends::all()))
        .iter()
        .map(AdapterSummary::of)
        .collect()
}

/// Preference order for `--backend auto`: discrete, integrated, virtual GPUs.
fn rank(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// What to open.
#[derive(Debug, Clone, Default)]
pub struct AdapterRequest {
    /// Case-insensitive substring of the adapter name (`--adapter`).
    pub name: Option<String>,
    /// Accept a software adapter (llvmpipe). `--backend gpu` does; `auto` does not.
    pub allow_software: bool,
    /// Use the compare-exchange loop even when float atomics exist (tests).
    pub force_cas: bool,
}

/// Opens the adapter `req` asks for. Errors say what was found instead.
pub fn open(req: &AdapterRequest) -> Result<GpuContext> {
    let inst = instance();
    let mut list = pollster::block_on(inst.enumerate_adapters(wgpu::Backends::all()));
    list.sort_by_key(|a| rank(a.get_info().device_type));
    let found: Vec<String> = list.iter().map(|a| AdapterSummary::of(a).label()).collect();
    let chosen = list.into_iter().find(|a| {
        let s = AdapterSummary::of(a);
        let name_ok = req
            .name
            .as_ref()
            .is_none_or(|n| s.name.to_lowercase().contains(&n.to_lowercase()));
        name_ok && (req.allow_software || !s.is_software() || req.name.is_some())
    });
    let Some(adapter) = chosen else {
        let what = match &req.name {
            Some(n) => format!("no adapter matches --adapter {n:?}"),
            None if req.allow_software => "no adapter found".to_string(),
            None => "no hardware GPU adapter found".to_string(),
        };
        let seen = if found.is_empty() {
            "wgpu sees no adapter at all (install a Vulkan driver, e.g. mesa-vulkan-drivers for the llvmpipe software adapter)".to_string()
        } else {
            format!("adapters seen: {}", found.join("; "))
        };
        return Err(Error::NoAdapter(format!("{what}; {seen}")));
    };
    let summary = AdapterSummary::of(&adapter);
    let atomics = if summary.float_atomics && !req.force_cas {
        AtomicMode::Float
    } else {
        AtomicMode::CompareExchange
    };
    let features = match atomics {
        AtomicMode::Float => wgpu::Features::SHADER_FLOAT32_ATOMIC,
        AtomicMode::CompareExchange => wgpu::Features::empty(),
    };
    // Ask for the adapter's own limits: the largest bindings and the most
    // storage buffers per stage it offers (wgpu's defaults are far lower).
    let limits = adapter.limits();
    let desc = wgpu::DeviceDescriptor {
        label: Some("lme-mpm"),
        required_features: features,
        required_limits: limits.clone(),
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&desc))
        .map_err(|e| Error::Gpu(format!("cannot open {}: {e}", summary.label())))?;
    Ok(GpuContext {
        device,
        queue,
        adapter: summary,
        atomics,
        limits,
    })
}
