//! Byte transports: anything that is [`AsyncRead`] + [`AsyncWrite`] carries
//! a protocol. This module provides the real serial port ([`serial`]), an
//! in-memory duplex ([`memory`]), a seeded fault injector ([`fault`]) and a
//! traffic log ([`traffic_log`]); the wrappers compose.

pub mod fault;
pub mod memory;
pub mod serial;
pub mod traffic_log;

use tokio::io::{AsyncRead, AsyncWrite};

/// A byte stream a host driver or an emulator can use.
pub trait Transport: AsyncRead + AsyncWrite + Unpin + Send {}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> Transport for T {}
