//! Byte links to device firmware. The protocols land with their issue; see the README table.
