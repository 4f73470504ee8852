-- fuzz case: pcall(tr.meta, tr, {}) named the method '?'
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["trajectory:meta"](P["traj"], H["t_empty"], H["one"])
end
