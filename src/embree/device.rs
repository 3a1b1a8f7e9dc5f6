//! The Embree device: its configuration string, its error log, and what the
//! loaded library turned out to be (version, hit-record layout).

use std::ffi::{CStr, CString, c_char, c_void};
use std::sync::{Mutex, OnceLock};

use embree4_sys as sys;

use crate::embree::EmbreeError;

/// The device configuration the comparisons use: Embree's 8-wide AVX2 kernels,
/// which match raypack's 8-wide packets, and one build thread. (Tracing runs on
/// the caller's threads whatever `threads` says; it only sizes Embree's BVH
/// builder.) Against Embree's own choice (AVX-512 where the CPU has it) see
/// `docs/measurements.md`, "Embree side by side".
pub const DEFAULT_CONFIG: &str = crate::embree_settings::DEFAULT_EMBREE_CONFIG;

/// Errors Embree reported through its error callback, oldest first.
#[derive(Debug, Default)]
struct ErrorLog(Mutex<Vec<String>>);

impl ErrorLog {
    fn push(&self, message: String) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push(message);
    }

    fn take(&self) -> Vec<String> {
        std::mem::take(&mut *self.0.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

/// Embree's error callback: record the message for [`Device::check`].
unsafe extern "C" fn record_error(user: *mut c_void, code: sys::RTCError, message: *const c_char) {
    // SAFETY: `user` is the `ErrorLog` the device owns (boxed, so it does not
    // move), registered in `Device::new` and valid until the device is released.
    let log = unsafe { &*(user as *const ErrorLog) };
    let text = if message.is_null() {
        String::new()
    } else {
        // SAFETY: Embree passes a NUL-terminated string valid for this call.
        unsafe { CStr::from_ptr(message) }.to_string_lossy().into_owned()
    };
    log.push(format!("{code:?}: {text}"));
}

/// An Embree device (`RTCDevice`) and what it reported about itself.
pub struct Device {
    raw: sys::RTCDevice,
    /// Errors reported by callback; boxed so its address stays valid for Embree.
    errors: Box<ErrorLog>,
    config: String,
    version: u32,
    /// Whether the library writes `instPrimID` after the hit record, once
    /// probed (`Device::writes_inst_prim_id`, in `layout_probe.rs`).
    pub(crate) inst_prim_id: OnceLock<bool>,
}

// SAFETY: Embree's device API is thread-safe; the error log is behind a mutex.
unsafe impl Send for Device {}
// SAFETY: as above.
unsafe impl Sync for Device {}

impl Device {
    /// A device with Embree's configuration string `config` (comma-separated
    /// `key=value`: `threads`, `isa`, `verbose`, …; see [`DEFAULT_CONFIG`]).
    pub fn new(config: &str) -> Result<Self, EmbreeError> {
        let device_error = |message: String| EmbreeError::Device {
            config: config.to_string(),
            message,
        };
        let c_config = CString::new(config).map_err(|_| device_error("config contains a NUL byte".into()))?;
        // Embree checks FTZ/DAZ on the creating thread too.
        crate::embree::flush_denormals();
        // SAFETY: a valid NUL-terminated string; a null result is handled below.
        let raw = unsafe { sys::rtcNewDevice(c_config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: a null device asks for the error of the failed creation.
            let code = unsafe { sys::rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(device_error(format!("{code:?}")));
        }
        let errors = Box::<ErrorLog>::default();
        // SAFETY: the log outlives the device (released in Drop before the box).
        unsafe {
            sys::rtcSetDeviceErrorFunction(
                raw,
                Some(record_error),
                &*errors as *const ErrorLog as *mut c_void,
            );
        }
        // SAFETY: a valid device.
        let version = unsafe { sys::rtcGetDeviceProperty(raw, sys::RTCDeviceProperty::VERSION) } as u32;
        let device = Self {
            raw,
            errors,
            config: config.to_string(),
            version,
            inst_prim_id: OnceLock::new(),
        };
        device.check("creating the device")?;
        Ok(device)
    }

    /// The device with [`DEFAULT_CONFIG`].
    pub fn with_default_config() -> Result<Self, EmbreeError> {
        Self::new(DEFAULT_CONFIG)
    }

    /// The raw handle.
    pub(crate) fn raw(&self) -> sys::RTCDevice {
        self.raw
    }

    /// The configuration string the device was made with.
    pub fn config(&self) -> &str {
        &self.config
    }

    /// The library's version as `major·10000 + minor·100 + patch` (40400 for 4.4.0).
    pub fn version(&self) -> u32 {
        self.version
    }

    /// The library's version as `major.minor.patch`.
    pub fn version_string(&self) -> String {
        format!(
            "{}.{}.{}",
            self.version / 10000,
            self.version / 100 % 100,
            self.version % 100
        )
    }

    /// Fail with everything Embree reported since the last check, if anything.
    pub(crate) fn check(&self, step: &'static str) -> Result<(), EmbreeError> {
        let mut messages = self.errors.take();
        // SAFETY: a valid device; reading its sticky error code also clears it.
        let code = unsafe { sys::rtcGetDeviceError(self.raw) };
        if code != sys::RTCError::NONE && messages.is_empty() {
            messages.push(format!("{code:?}"));
        }
        if messages.is_empty() {
            Ok(())
        } else {
            Err(EmbreeError::Api {
                step,
                message: messages.join("; "),
            })
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: the device was made by rtcNewDevice and is released once; scenes
        // hold their own reference (and an `Arc<Device>`), so none is left using it.
        unsafe { sys::rtcReleaseDevice(self.raw) };
    }
}

/// The device as the environment of a result records it.
impl From<&Device> for crate::environment::EmbreeInfo {
    fn from(device: &Device) -> Self {
        Self {
            version: device.version_string(),
            config: device.config().to_string(),
        }
    }
}

impl std::fmt::Debug for Device {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Device")
            .field("config", &self.config)
            .field("version", &self.version_string())
            .field("inst_prim_id", &self.inst_prim_id)
            .finish()
    }
}
