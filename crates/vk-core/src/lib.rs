//! Vulkan plumbing.
