//! The RT executive on a thread of its own, for the tests that drive it through the hand-off.

/// Starts the RT executive of `cell` on a thread of its own, over the simulated bus, with its
/// end of the hand-off and the setpoint subscriber it opens there (the port is not `Send`).
pub fn spawn_rt(
    cell: &cellrt_config::CellConfig,
    rt_end: cellrt_runtime::handoff::RtEnd,
    hook: Option<cellrt_runtime::rt::executive::PhaseHook>,
) -> std::thread::JoinHandle<cellrt_runtime::rt::executive::RtStats> {
    use cellrt_runtime::host::cell_bus::sim_bus;
    use cellrt_runtime::rt::executive::Executive;
    use cellrt_runtime::rt::setpoint_stream::SetpointStream;
    use cellrt_runtime::services;
    let c = cell.clone();
    std::thread::spawn(move || {
        let node = services::node(&c.name, "rt").unwrap();
        let sub = services::setpoint_subscriber(&node, &c.name).unwrap();
        Executive::new(&c, sim_bus(&c), SetpointStream::new(sub), rt_end, hook).run()
    })
}
