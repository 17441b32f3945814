-- Ardour 7 headless (Dummy backend): load Rosin as the instrument of a MIDI track in each
-- format, play a note into it, and check that the track meter moves. Run by scripts/ardour-check.sh.
local formats = { { "LV2", ARDOUR.PluginType.LV2 }, { "VST3", ARDOUR.PluginType.VST3 } }
assert (AudioEngine:set_backend ("None (Dummy)", "", ""), "no Dummy backend")
local session = create_session (os.getenv ("ROSIN_ARDOUR_SESSION"), "rosin-check", 48000)
assert (session, "cannot create a session")
local failures = 0
for _, f in ipairs (formats) do
	local info = nil
	for p in ARDOUR.LuaAPI.list_plugins ():iter () do
		if p.name == "Rosin" and p.type == f[2] then info = p end
	end
	if not info then
		print ("FAIL " .. f[1] .. ": Ardour does not list Rosin")
		failures = failures + 1
	else
		local tracks = session:new_midi_track (ARDOUR.ChanCount (ARDOUR.DataType ("midi"), 1),
			ARDOUR.ChanCount (ARDOUR.DataType ("audio"), 2), true, info, nil, nil, 1, "rosin-" .. f[1],
			ARDOUR.PresentationInfo.max_order, ARDOUR.TrackMode.Normal, true, false)
		local track = tracks:front ()
		local insert = track:the_instrument ():to_plugininsert ()
		local name = insert:isnil () and "(none)" or insert:name ()
		ARDOUR.LuaAPI.usleep (700000)
		local before = track:peak_meter ():meter_level (0, ARDOUR.MeterType.MeterPeak)
		-- Note on D3 straight into the instrument (Ardour parses the bytes into its own buffer).
		local parser = ARDOUR.RawMidiParser ()
		for _, b in ipairs ({ 0x90, 50, 100 }) do parser:process_byte (b) end
		local sent = false
		if not insert:isnil () then
			local ok, result = pcall (function ()
				return insert:write_immediate_event (Evoral.EventType.MIDI_EVENT, parser:buffer_size (), parser:midi_buffer ())
			end)
			if not ok then ok, result = pcall (function () return insert:write_immediate_event (parser:buffer_size (), parser:midi_buffer ()) end) end
			sent = ok and result
		end
		-- The Dummy backend runs process cycles meanwhile; on a loaded machine it may take a while.
		local level = 0
		for _ = 1, 20 do
			ARDOUR.LuaAPI.usleep (500000)
			level = track:peak_meter ():meter_level (0, ARDOUR.MeterType.MeterPeak)
			if level > 1e-2 then break end
		end
		-- MeterPeak reads as a linear peak here (0 = silence).
		local good = sent and before < 1e-4 and level > 1e-2
		print (string.format ("%s %s: instrument '%s', track peak %.4f before the note, %.4f after", good and "OK  " or "FAIL",
			f[1], name, before, level))
		if not good then failures = failures + 1 end
	end
end
close_session ()
print (failures == 0 and "ardour check passed" or "ardour check FAILED")
if failures > 0 then os.exit (1) end
quit ()
